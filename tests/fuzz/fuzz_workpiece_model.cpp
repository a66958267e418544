// libFuzzer harness: workpiece model files (workpiece/model.h LoadWorkpieceModel: the network
// file of nn/model.h and the family-choice file of family/family.h), then what every predicting
// command does with one: a prediction inside and one far outside the training domain, and the
// network that crosscheck and export ask for. Bad input must be an InputError that names its
// rule; any other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
#include "core/error.h"
#include "fuzz_file.h"
#include "workpiece/model.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".json");
  try {
    const whirl::workpiece::WorkpieceModel m = whirl::workpiece::LoadWorkpieceModel(path);
    (void)m.Describe();
    for (const whirl::ProcessInputs& in :
         {whirl::ProcessInputs{62, 80, 10, 3.7, 180}, whirl::ProcessInputs{20, 499, 99, 49, 999}})
      (void)whirl::workpiece::Predict(m, in);
  } catch (const whirl::InputError& e) {
    whirl::fuzz::Refused(e);
  }
  try {
    (void)whirl::workpiece::LoadNetworkModel(path, "crosscheck");
  } catch (const whirl::InputError& e) {
    whirl::fuzz::Refused(e);
  }
  return 0;
}
