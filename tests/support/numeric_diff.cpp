// numeric_diff: compares two text files (CSV, JSON) with a stated tolerance on numbers.
//   numeric_diff [--rel R] [--abs A] [--skip-comments] expected actual
// Both files are split into numbers (strtod syntax) and the text between them. The text must be
// identical; numbers a (expected) and b (actual) must satisfy |a - b| <= A + R max(|a|, |b|)
// (defaults R = 1e-6, A = 1e-9). --skip-comments drops lines starting with '#'.
// Exit 0 when equal within tolerance, 1 on the first difference (printed with its line), 2 on
// usage or I/O errors. Used by the reproduction tests: other compilers or flags (FMA with
// -march=x86-64-v3) change the last digits, not the result.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

namespace {

std::string Read(const char* path, bool skip_comments) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    std::fprintf(stderr, "numeric_diff: cannot open %s\n", path);
    std::exit(2);
  }
  std::string out, line;
  while (std::getline(in, line))
    if (!(skip_comments && !line.empty() && line[0] == '#')) out += line + "\n";
  return out;
}

// A number starts here: [+-]?(digit | .digit). Returns its length (0 if none) and value.
std::size_t NumberAt(const std::string& s, std::size_t i, double* value) {
  std::size_t j = i;
  if (j < s.size() && (s[j] == '-' || s[j] == '+')) ++j;
  const bool digit = j < s.size() && std::isdigit(static_cast<unsigned char>(s[j]));
  const bool dot_digit =
      j + 1 < s.size() && s[j] == '.' && std::isdigit(static_cast<unsigned char>(s[j + 1]));
  if (!digit && !dot_digit) return 0;
  // A number glued to a word (e.g. "x86", "sd43900") is text, not a value.
  if (i > 0 && (std::isalpha(static_cast<unsigned char>(s[i - 1])) || s[i - 1] == '_')) return 0;
  char* end = nullptr;
  *value = std::strtod(s.c_str() + i, &end);
  return static_cast<std::size_t>(end - (s.c_str() + i));
}

int LineOf(const std::string& s, std::size_t pos) {
  int line = 1;
  for (std::size_t k = 0; k < pos && k < s.size(); ++k) line += s[k] == '\n';
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  double rel = 1e-6, abs_tol = 1e-9;
  bool skip_comments = false;
  const char* files[2] = {nullptr, nullptr};
  int n_files = 0;
  for (int k = 1; k < argc; ++k) {
    if (!std::strcmp(argv[k], "--rel") && k + 1 < argc) {
      rel = std::atof(argv[++k]);
    } else if (!std::strcmp(argv[k], "--abs") && k + 1 < argc) {
      abs_tol = std::atof(argv[++k]);
    } else if (!std::strcmp(argv[k], "--skip-comments")) {
      skip_comments = true;
    } else if (n_files < 2) {
      files[n_files++] = argv[k];
    } else {
      n_files = 3;
    }
  }
  if (n_files != 2) {
    std::fprintf(stderr,
                 "usage: numeric_diff [--rel R] [--abs A] [--skip-comments] expected actual\n");
    return 2;
  }
  const std::string a = Read(files[0], skip_comments), b = Read(files[1], skip_comments);
  std::size_t i = 0, j = 0, numbers = 0;
  double worst_rel = 0;
  while (i < a.size() || j < b.size()) {
    double x = 0, y = 0;
    const std::size_t la = i < a.size() ? NumberAt(a, i, &x) : 0;
    const std::size_t lb = j < b.size() ? NumberAt(b, j, &y) : 0;
    if (la > 0 && lb > 0) {
      const double scale = std::max(std::fabs(x), std::fabs(y));
      if (!(std::fabs(x - y) <= abs_tol + rel * scale)) {
        std::fprintf(stderr,
                     "numeric_diff: line %d of %s: %s vs %s (|diff| %.3g > %.3g + %.3g * %.3g)\n",
                     LineOf(a, i), files[1], a.substr(i, la).c_str(), b.substr(j, lb).c_str(),
                     std::fabs(x - y), abs_tol, rel, scale);
        return 1;
      }
      if (scale > 0) worst_rel = std::max(worst_rel, std::fabs(x - y) / scale);
      ++numbers;
      i += la;
      j += lb;
    } else if (la == 0 && lb == 0 && i < a.size() && j < b.size() && a[i] == b[j]) {
      ++i;
      ++j;
    } else {
      std::fprintf(stderr, "numeric_diff: line %d of %s: text differs: '%s' vs '%s'\n",
                   LineOf(a, i), files[1], a.substr(i, 40).c_str(), b.substr(j, 40).c_str());
      return 1;
    }
  }
  std::printf(
      "numeric_diff: %zu numbers equal within rel %.3g, abs %.3g (largest relative "
      "difference %.3g)\n",
      numbers, rel, abs_tol, worst_rel);
  return 0;
}
