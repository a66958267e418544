#pragma once
// Per-point models from the drift module (src/product/drift): for each position-tagged error
// column (per_point.h), Miao et al.'s sensitive-point selection and multiple linear regression
// (drift::FitDriftModel, kind mlr by default; any drift::FitOptions works) fitted on the training
// runs, then drift::PredictRun on the target run: the PointModelFn of per_point.h.
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "drift/fit.h"
#include "drift/model.h"
#include "surface/per_point.h"

namespace whirl::surface {

/// What each point's model chose (thread-safe: the models run in parallel).
struct DriftPointNotes {
  std::mutex mutex;
  std::map<std::string, std::string> by_column;  ///< column -> "sensors a_C, b_C; R^2 ...; ..."
};

/// The training runs and the target run must outlive the returned function. `notes` may be null.
PointModelFn DriftPointModel(const std::vector<drift::Run>& training, const drift::Run& target,
                             drift::FitOptions options, DriftPointNotes* notes = nullptr);

}  // namespace whirl::surface
