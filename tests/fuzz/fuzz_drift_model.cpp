// libFuzzer harness: drift model files (drift/model.h ReadDriftModel). Bad input must be an InputError; any
// other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
#include "core/error.h"
#include "drift/model.h"
#include "fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".json");
  try {
    (void)whirl::drift::ReadDriftModel(path);
  } catch (const whirl::InputError&) {
  }
  return 0;
}
