// Every trained number of a joint drift model as JSON (inputs, time constants, coefficients, the
// cross-validated error), so a test can compare two trainings byte for byte. One copy for the
// machine-evaluation tests (they are compiled as one unity batch).
#pragma once

#include <nlohmann/json.hpp>
#include <vector>

#include "drift/joint.h"

namespace whirl::machine_eval::testing_support {

inline nlohmann::json TrainedNumbers(const drift::JointDriftModel& m) {
  return {{"sensors", m.sensors},
          {"others", m.other_inputs},
          {"taus", m.time_constants},
          {"a", std::vector<double>(m.a.data(), m.a.data() + m.a.size())},
          {"g", std::vector<double>(m.g.data(), m.g.data() + m.g.size())},
          {"cv", m.cv_rmse_um}};
}

}  // namespace whirl::machine_eval::testing_support
