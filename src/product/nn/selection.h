#pragma once
// Choosing the hidden size the way the paper did (grow from 4 until the error stops improving,
// Li, Ma and Jiang's whirling paper), with numbers a user can judge: training error, gamma
// (effective number of parameters), log evidence and k-fold cross-validation error per hidden size.
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "core/process.h"
#include "nn/trainbr.h"

namespace whirl::nn {

struct SweepOptions {
  int hidden_min = 4;      ///< first hidden size (one tansig layer)
  int hidden_max = 8;      ///< last hidden size, inclusive
  int folds = 5;           ///< k of k-fold cross-validation, 2 <= k <= rows
  std::uint64_t seed = 1;  ///< restart r of every fit initializes with seed + r
  int restarts = 1;        ///< restarts per fit (best log evidence kept)
  TrainOptions train;      ///< trainbr options
  /// Fits (sizes x (folds + 1)) run on this many threads (core/parallel.h; <= 0: all cores);
  /// the rows are identical for any thread count.
  int threads = 0;
  void Validate(int rows) const;  ///< InputError naming the option, value and rule
};

/// One hidden size. Errors in original units per output (max_elongation_um, settle_time_s).
struct SweepRow {
  int hidden = 0;
  int parameter_count = 0;          ///< N
  double train_sse_normalized = 0;  ///< ssE of the fit on all rows
  Eigen::VectorXd train_rms;        ///< per output, original units
  double gamma = 0;                 ///< effective number of parameters of the full fit
  double log_evidence = 0;          ///< of the full fit (nn/trainbr.h LogEvidence)
  Eigen::VectorXd cv_rms;           ///< k-fold CV RMS error per output, original units
  /// sqrt(mean over outputs and rows of (CV error / full-data half range)^2): both outputs count
  /// equally, as in training (error_space "normalized").
  double cv_rms_normalized = 0;
};
void to_json(nlohmann::json& j, const SweepRow& r);

/// Row q is held out in fold q % folds (deterministic). Each fold fits mapminmax on its own
/// training rows (no information from the held-out rows) and trains with the same seed/restarts.
/// `progress(done, total)` counts finished fits (sizes x (folds + 1)), called under a lock.
std::vector<SweepRow> HiddenSweep(const ProcessTable& table, const SweepOptions& options,
                                  const std::function<void(int, int)>& progress = {});

}  // namespace whirl::nn
