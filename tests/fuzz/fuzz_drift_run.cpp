// libFuzzer harness: drift run files (drift/run_file.h ReadRun). Bad input must be an InputError; any
// other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
#include "core/error.h"
#include "drift/run_file.h"
#include "fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    (void)whirl::drift::ReadRun(path, whirl::drift::RunState::kUnknown);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
