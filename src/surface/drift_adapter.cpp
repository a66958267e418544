#include "surface/drift_adapter.h"

#include <cstdio>

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
      char buf[96];
      std::snprintf(buf, sizeof buf, "; R^2 %.4f, residual std %.3f um", fit.model.r_squared,
                    fit.model.residual_std_um);
      const std::lock_guard<std::mutex> lock(notes->mutex);
      std::string left_out;
      for (const auto& w : fit.warnings) left_out += "; " + w;
      notes->by_column[column] =
          drift::ToString(fit.model.kind) + " on " + sensors + buf + left_out;
    }
    return std::vector<double>(p.predicted_um.data(),
                               p.predicted_um.data() + p.predicted_um.size());
  };
}

}  // namespace whirl::surface
