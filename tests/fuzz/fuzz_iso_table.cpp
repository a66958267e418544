// libFuzzer harness: ISO 3408-3 tolerance tables (compare/iso3408.h). Bad input must be an
// InputError; any other exception, crash, hang, leak or sanitizer report is a bug
// (tests/fuzz/README.md).
#include "compare/iso3408.h"
#include "core/error.h"
#include "fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    (void)whirl::compare::ReadIsoToleranceTable(path);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
