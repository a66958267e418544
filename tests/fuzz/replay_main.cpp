// The fuzz corpora as a plain test (CTest corpus_<harness>, default suite, any compiler): every
// file under the given files and directories is handed once to the harness's entry point, as
// libFuzzer would hand it (a finding aborts: crash, exception other than InputError, a refusal
// that names no rule, a non-finite result where the harness requires one). Under an ASan/UBSan
// build (scripts/sanitize.sh) the same replay runs with the sanitizers.
// Usage: fuzz_corpus <harness> <file or directory>...
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "corpus_harnesses.h"  // generated: the harnesses' renamed entry points (kHarnesses)

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: fuzz_corpus <harness> <file or directory>...\n");
    return 2;
  }
  const auto harness = std::find_if(std::begin(kHarnesses), std::end(kHarnesses),
                                    [&](const Harness& h) { return std::strcmp(h.name, argv[1]) == 0; });
  if (harness == std::end(kHarnesses)) {
    std::fprintf(stderr, "fuzz_corpus: no harness '%s'\n", argv[1]);
    return 2;
  }
  std::vector<fs::path> files;
  for (int i = 2; i < argc; ++i) {
    std::error_code ec;
    if (fs::is_directory(argv[i], ec)) {
      for (fs::recursive_directory_iterator it(argv[i], ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file(ec)) files.push_back(it->path());
    } else if (fs::is_regular_file(argv[i], ec)) {
      files.emplace_back(argv[i]);
    }  // a corpus directory that does not exist yet holds nothing
  }
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) {
    std::ifstream in(f, std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    std::fprintf(stderr, "%s\n", f.c_str());  // the last line names the input of a finding
    harness->run(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
  }
  std::printf("fuzz_corpus %s: %zu inputs, no finding\n", argv[1], files.size());
  return files.empty() ? 1 : 0;  // no input at all is a broken test, not a pass
}
