// libFuzzer harness: machine profiles (interp/machine_profile.h LoadMachineProfile). Bad input must be an InputError; any
// other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
#include "core/error.h"
#include "interp/machine_profile.h"
#include "fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".json");
  try {
    (void)whirl::interp::LoadMachineProfile(path);
  } catch (const whirl::InputError&) {
  }
  return 0;
}
