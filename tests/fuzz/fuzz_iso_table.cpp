// libFuzzer harness: ISO 3408-3 tolerance tables (lead/iso3408.h). Bad input must be an
// InputError; any other exception, crash, hang, leak or sanitizer report is a bug
// (tests/fuzz/README.md).
#include "lead/iso3408.h"
#include "core/error.h"
#include "fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    (void)whirl::lead::ReadIsoToleranceTable(path);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
