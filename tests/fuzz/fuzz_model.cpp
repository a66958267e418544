// libFuzzer harness: model files (nn/model.h LoadModel, then one prediction). Bad input must be an
// InputError; any other exception, crash, hang, leak or sanitizer report is a bug
// (tests/fuzz/README.md).
#include "core/error.h"
#include "fuzz_file.h"
#include "nn/model.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".json");
  try {
    const whirl::nn::Model m = whirl::nn::LoadModel(path);
    (void)whirl::nn::Predict(m, whirl::ProcessInputs{62, 80, 10, 3.7, 180});
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
