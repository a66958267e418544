#include "core/safe_text.h"

namespace whirl {

std::string HtmlEscape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        if ((u < 0x20 && ch != '\t' && ch != '\n') || u == 0x7f)
          out += "\xEF\xBF\xBD";  // U+FFFD
        else
          out += ch;
    }
  }
  return out;
}

std::string GnuplotString(std::string_view text) {
  std::string out = "'";
  for (const char ch : text) {
    const auto u = static_cast<unsigned char>(ch);
    if (ch == '\'')
      out += "''";
    else if (u < 0x20 || u == 0x7f)
      out += ' ';
    else
      out += ch;
  }
  return out + "'";
}

std::string Slug(std::string_view text, std::size_t max_length) {
  std::string out;
  for (const char ch : text) {
    if (out.size() >= max_length) break;
    const bool keep = (ch >= 'a' && ch <= 'z') || (ch >= 'A' && ch <= 'Z') ||
                      (ch >= '0' && ch <= '9') || ch == '-' || ch == '_' || ch == '.';
    out += keep ? ch : '_';
  }
  if (out.empty()) return "x";
  if (out.front() == '.' || out.front() == '-') out.front() = '_';
  return out;
}

}  // namespace whirl
