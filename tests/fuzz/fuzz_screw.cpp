// libFuzzer harness: screw files (screw/screw.h ReadScrew). Bad input must be an InputError; any
// other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
#include "core/error.h"
#include "fuzz_file.h"
#include "screw/screw.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".json");
  try {
    (void)whirl::screw::ReadScrew(path);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
