#pragma once
// Evaluation of drift models:
//  - cross-run evaluation as Miao et al.'s tables 6-8: a model built on each run (its own sensor
//    selection) predicts every run; RMSE, std and max |.| of the prediction error e - e_hat [um]
//    per pair, beside "no compensation" (e_hat = 0: the statistics of the error itself) and "MLR
//    on all sensors". Group means over ordered pairs of different runs (train != test) by state:
//    "idle on idle", "idle on cutting", "cutting on cutting", "cutting on idle" (and "unknown"
//    pairs); the diagonal (a model on its own training run) is reported apart as "own run" (a fit,
//    not a prediction). Predictions use each test run's first row as reference (ReferenceMode::
//    kRunStart), as training does.
//  - chronological hold-out on one long log (FL_THERMAL's split): train on rows [0, a Q), test on
//    [a Q, (a + b) Q); the model runs from row 0 (lags and reference start at the log's start, as
//    on a machine that is never reset) and is scored on the test rows only.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "drift/fit.h"
#include "drift/model.h"

namespace whirl::drift {

struct ErrorStats {
  int samples = 0;
  double mae_um = 0;      ///< mean |r|
  double rmse_um = 0;     ///< sqrt(mean r^2)
  double std_um = 0;      ///< population std of r (Miao et al.'s "prediction std")
  double max_abs_um = 0;  ///< max |r|
};
ErrorStats ComputeErrorStats(const Eigen::VectorXd& residual_um);

/// ComputeErrorStats over residuals that arrive one at a time (a streamed run): sums of |r| and
/// r^2, the maximum, and the mean and sum of squared deviations by Welford's update (Chan,
/// Golub and LeVeque's merge for Merge), so the memory is fixed; equal to ComputeErrorStats up to
/// rounding.
class ErrorStatsAccumulator {
 public:
  void Add(double r) {
    ++n_;
    abs_ += std::abs(r);
    sq_ += r * r;
    max_ = std::max(max_, std::abs(r));
    const double d = r - mean_;
    mean_ += d / static_cast<double>(n_);
    m2_ += d * (r - mean_);
  }
  void Merge(const ErrorStatsAccumulator& o);
  long long count() const { return n_; }
  ErrorStats Stats() const;

 private:
  long long n_ = 0;
  double abs_ = 0, sq_ = 0, max_ = 0, mean_ = 0, m2_ = 0;
};

// Every figure below is on one error zero (FitOptions::zero, run_file.h ErrorZero): the models,
// "no compensation" and the sensor-free baselines alike, so gains are comparable.

struct CrossRunCell {
  ErrorStats model;        ///< the selected-sensor model of the training run
  ErrorStats all_sensors;  ///< MLR on every sensor of the training run
  ErrorStats none;         ///< no compensation (the test run's error on the zero)
  ErrorStats time;         ///< sensor-free: the training run's time-only warm-up model
};

struct CrossRunGroup {
  std::string name;  ///< "idle on cutting" = trained idle, tested cutting; "own run"
  int pairs = 0;
  ErrorStats model, all_sensors, none, time;  ///< means of each statistic over the pairs
  /// The lowest mean RMSE of the group: "model", "mlr_all", "none" or "time".
  std::string Strongest() const;
};

struct CrossRunResult {
  std::string error_column;
  ModelKind kind = ModelKind::kMlr;
  std::vector<std::string> runs;
  std::vector<RunState> states;
  Candidates candidates = Candidates::kAuto;      ///< the families each run's model chose from
  /// Inputs of each run's model: its sensors, then "elapsed time (tau ...)" when it has
  /// elapsed-time terms.
  std::vector<std::vector<std::string>> chosen;
  std::vector<std::vector<CrossRunCell>> cells;  ///< [train][test]
  std::vector<CrossRunGroup> groups;
  std::vector<DriftModel> models;  ///< each run's model
  std::vector<std::string> warnings;  ///< sensors the fits left out (FitReport::warnings), once
  ZeroConvention zero;                ///< the zero of every figure
};

/// Builds one model per run as drift fit does (options.kind, options.candidates: by default the
/// choice between the sensors and the time models; Miao et al.'s selection unless options.sensors
/// is set; --candidates sensors gives Miao et al.'s table) and a time-only warm-up model per run,
/// and predicts every run, all on options.zero (a fixed zero without a level: the first run's
/// first row). Runs need at least 2 entries and the error column. Parallel over runs.
CrossRunResult CrossRun(const std::vector<Run>& runs, const std::string& error_column,
                        const FitOptions& options);

struct HoldoutOptions {
  double train_fraction = 0.6;        ///< first part of the rows for training, in (0, 1)
  double test_fraction = 0.2;         ///< next part for testing; train + test <= 1
  /// The selection's class count is capped here (0: no limit, as drift fit; the fewest rule
  /// rarely reaches a cap, --classes cv may keep many sensors).
  int max_sensors = 0;
  std::vector<std::string> channels;  ///< error columns (empty: every _um column)
  /// Methods: none, fit (drift fit at fit.candidates, default auto: the choice between the
  /// sensors and the time models; kind mlr, no sensor cap), time (sensor-free: time-only warm-up
  /// since the log's start, 1 or 2 terms by validation), mlr_all (MLR on every sensor), mlr
  /// (selected), dynamic (selected, lags),
  /// network (selected, k-h-1), and dynamic_extra (selected + the extra inputs, lags) when
  /// fit.extra_inputs is not empty. All on fit.zero (run-start: from the log's first row).
  bool network = true;
  FitOptions fit;  ///< lag grid, network settings, selection options, extra inputs
};

struct HoldoutRow {
  std::string channel;
  std::string method;
  std::vector<std::string> inputs;  ///< sensors (and extra inputs) used
  std::vector<double> time_constants;
  ErrorStats train, test;
};

struct HoldoutResult {
  std::string log;
  int rows = 0, train_end = 0, test_end = 0;
  double train_end_min = 0, test_end_min = 0;  ///< sample indices when time_from_index
  bool time_from_index = false;                ///< the log recorded no time
  std::vector<HoldoutRow> rows_out;
  std::vector<DriftModel> models;          ///< same order as rows_out (none: an empty model)
  std::vector<RunPrediction> predictions;  ///< on rows [0, test_end), same order
  std::vector<std::string> warnings;       ///< sensors the fits left out, once each
  ZeroConvention zero;                     ///< the zero of every figure
  /// Per channel, the method with the lowest test MAE, and the lowest without a sensor.
  std::vector<std::pair<std::string, std::string>> Strongest() const;  ///< (channel, method)
};

/// Every method a hold-out row can name (HoldoutOptions' list, in the order Holdout adds them):
/// none, fit, time, mlr_all, mlr, dynamic, network, dynamic_extra. The report draws each in its
/// look of core/plot_style.h.
const std::vector<std::string>& HoldoutMethods();

HoldoutResult Holdout(const Run& log, const HoldoutOptions& options,
                      const std::function<void(const std::string&)>& progress = {});

}  // namespace whirl::drift
