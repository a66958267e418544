// libFuzzer harness: drift model files (drift/model.h ReadDriftModel), then every use a command
// makes of a model that loads: a prediction on a short run with the model's columns (drift
// predict, monitor), the NC program, its PLC table and the plan-combined program (drift nc). Bad
// input must be an InputError that names its rule; any other exception, crash, hang, leak or
// sanitizer report is a bug (tests/fuzz/README.md).
#include <string>

#include "core/error.h"
#include "drift/model.h"
#include "fuzz_file.h"
#include "interp/drift_action.h"

namespace {

using whirl::fuzz::Refused;

// A 12-sample run holding the model's sensors, extra inputs and error column, time in minutes.
whirl::drift::Run RunFor(const whirl::drift::DriftModel& m) {
  std::string header = "time_min", rows;
  for (const auto& s : m.sensors) header += "," + s;
  for (const auto& x : m.extra_inputs) header += "," + x;
  header += "," + m.error_column;
  for (int k = 0; k < 12; ++k) {
    rows += std::to_string(5 * k);
    for (std::size_t i = 0; i < m.sensors.size(); ++i)
      rows += "," + std::to_string(20.0 + 0.1 * k * static_cast<double>(i + 1));
    for (std::size_t i = 0; i < m.extra_inputs.size(); ++i) rows += "," + std::to_string(k % 3);
    rows += "," + std::to_string(0.5 * k) + "\n";
  }
  return whirl::drift::ParseRun(header + "\n" + rows, "synthetic.csv",
                                whirl::drift::RunState::kUnknown);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".json");
  whirl::drift::DriftModel m;
  try {
    m = whirl::drift::ReadDriftModel(path);
  } catch (const whirl::InputError& e) {
    Refused(e);
    return 0;
  }
  try {
    for (auto reference : {whirl::drift::ReferenceMode::kRunStart, whirl::drift::ReferenceMode::kModel})
      (void)whirl::drift::PredictRun(m, RunFor(m), reference);
  } catch (const whirl::InputError& e) {
    Refused(e);
  }
  whirl::interp::DriftActionOptions o;
  o.param_first = 100;
  o.sync_id_first = 150;
  o.sync_id_last = 255;
  int index = 1;
  for (const auto& s : m.sensors) o.inputs[s] = {index++ % 999 + 1, 0.1, 0.0};
  for (const auto& x : m.extra_inputs) o.inputs[x] = {index++ % 999 + 1, 1.0, 0.0};
  try {
    (void)whirl::interp::FormatDriftNcProgram(m, o);
    (void)whirl::interp::FormatDriftPlcCsv(m, o);
    o.workpiece_k0_param = 99;
    (void)whirl::interp::FormatDriftNcProgram(m, o);
  } catch (const whirl::InputError& e) {
    Refused(e);
  }
  return 0;
}
