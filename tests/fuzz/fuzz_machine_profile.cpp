// libFuzzer harness: machine profiles (interp/machine_profile.h LoadMachineProfile). Bad input must be an InputError; any
// other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
// The profile cross-checks: a profile that loads must be accepted by every use a command makes of
// it (tests/interp/profile_uses.h: plan and combined plan programs, drift programs with the
// smallest models, resets, PLC tables); a use that refuses it is a finding (one validation).
#include <cstdio>
#include <cstdlib>

#include "core/error.h"
#include "fuzz_file.h"
#include "interp/machine_profile.h"
#include "tests/interp/profile_uses.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".json");
  whirl::interp::MachineProfile profile;
  try {
    profile = whirl::interp::LoadMachineProfile(path);
  } catch (const whirl::InputError& e) {
    whirl::fuzz::Refused(e);
    return 0;
  }
  try {
    whirl::interp::testing::UseProfileEverywhere(profile);
  } catch (const whirl::InputError& e) {
    std::fprintf(stderr, "profile loaded, then refused by a command: %s\n", e.what());
    std::abort();
  }
  return 0;
}
