#include "surface/drift_adapter.h"

#include "core/numbers.h"

namespace whirl::surface {

PointModelFn DriftPointModel(const std::vector<drift::Run>& training, const drift::Run& target,
                             drift::FitOptions options, DriftPointNotes* notes) {
  options.threads = 1;  // the points already run in parallel (PredictAllPoints)
  options.candidates = drift::Candidates::kSensors;  // the sensor models as documented
  options.zero.zero = drift::ErrorZero::kAsLogged;     // the surface errors as logged
  return [&training, &target, options, notes](const std::string& column) {
    const drift::FitReport fit = drift::FitDriftModel(training, column, options);
    const drift::RunPrediction p = drift::PredictRun(fit.model, target);
    if (notes) {
      std::string sensors;
      for (const auto& s : fit.model.sensors) sensors += (sensors.empty() ? "" : ", ") + s;
      const std::string quality = "; R^2 " + FormatDecimals(fit.model.r_squared, 4) +
                                  ", residual std " + FormatDecimals(fit.model.residual_std_um, 3) +
                                  " um";
      const std::lock_guard<std::mutex> lock(notes->mutex);
      std::string left_out;
      for (const auto& w : fit.warnings) left_out += "; " + w;
      notes->by_column[column] =
          drift::ToString(fit.model.kind) + " on " + sensors + quality + left_out;
    }
    return std::vector<double>(p.predicted_um.data(),
                               p.predicted_um.data() + p.predicted_um.size());
  };
}

}  // namespace whirl::surface
