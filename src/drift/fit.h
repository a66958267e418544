#pragma once
// Fitting the drift models of drift/model.h on training runs: the choice of sensors (the fuzzy
// clustering and grey relational grades of Miao, Gao, Dang and Miao, "Analysis of the thermal
// error characteristics of CNC machine tools", Hefei University of Technology: drift/selection.h;
// or a class count by cross-validation), the lag search of the dynamic kind (greedy forward
// selection of time constants from FitOptions::tau_grid on the cross-validated RMSE) and the
// network kind's Bayesian-regularized training (nn/trainbr.h). drift/model.h says what each kind
// computes; this header, how it is fitted.
#include <cstdint>
#include <string>
#include <vector>

#include "drift/model.h"
#include "drift/run_file.h"
#include "drift/selection.h"
#include "nn/trainbr.h"

namespace whirl::drift {

struct FitOptions {
  ModelKind kind = ModelKind::kMlr;
  std::vector<std::string> sensors;  ///< empty: Miao et al.'s selection (selection.h)
  SelectionOptions selection;
  std::vector<std::string> extra_inputs;  ///< other columns used as inputs
  /// dynamic: candidate lag time constants [min, or samples without time]
  std::vector<double> tau_grid = {5, 10, 20, 40, 80, 160, 320};
  int max_lags = 2;  ///< dynamic: at most this many time constants (1..4)
  int folds = 5;     ///< dynamic: contiguous blocks when there is one training run (2..20)
  /// dynamic, one training run: forward-chaining folds (block k is predicted from blocks < k
  /// only, as a model is used on a machine: always forward in time) instead of leave-one-block-
  /// out. Several runs: always leave one run out.
  bool forward_cv = true;
  int hidden = 3;                ///< network: hidden tansig neurons h (1..20)
  int restarts = 3;              ///< network: trainbr restarts, the highest evidence kept (1..50)
  std::uint64_t seed = 1;        ///< network: Nguyen-Widrow seed of the first restart
  int max_train_samples = 3000;  ///< network: evenly thinned to at most this many samples
  nn::TrainOptions train;        ///< network: trainbr options (epochs default 1000)
  int threads = 0;               ///< cross-validation and restarts (0: all cores)
  void Validate() const;
};

struct LagSearchStep {
  std::vector<double> time_constants;
  double cv_rmse_um = 0;
};

struct FitReport {
  DriftModel model;
  bool selected = false;                  ///< sensors came from the selection
  Selection selection;                    ///< when selected
  std::vector<LagSearchStep> lag_search;  ///< dynamic: accepted steps, static first
  std::string train_report;               ///< network: trainbr BriefReport
  /// Sensors left out (selection.h convention 8: dead or duplicate), chosen or given, one line
  /// each naming the sensor and the runs.
  std::vector<std::string> warnings;
};

/// Miao et al.'s selection for a fit: SelectSensors (drift/selection.h) with options.selection, or,
/// for ClassCountRule::kCrossValidated, the class count chosen by cross-validation: for each
/// class count r the lambda-cuts offer (r <= max_classes when set), the sensors of SelectSensors
/// with kFixed r; their static MLR (no lags, plus the extra inputs) is scored by the pooled
/// out-of-sample RMSE over the folds of the dynamic kind's lag search (leave one run out with
/// several runs, else `folds` contiguous blocks, forward-chaining by default); the lowest RMSE
/// wins (ties: fewer classes). Selection::class_count_scores lists every candidate. The sensors
/// of each r are chosen on all runs (the clustering is unsupervised; the grey grades also see the
/// held-out run's error), so every candidate's RMSE is slightly optimistic alike. Why:
/// on the simulated whirling machine the fewest-significant rule keeps fewer sensors as training
/// runs are added and the combined compensation gets worse.
Selection SelectSensorsForFit(const std::vector<Run>& runs, const std::string& error_column,
                              const FitOptions& options);

/// Fits a model of `error_column` on `runs` (InputError on missing columns or bad options).
/// Dead and duplicate sensors (selection.h convention 8) are left out of the selection and of
/// given sensors, with a warning each (FitReport::warnings); InputError naming the run files when
/// no sensor is left, or when the regression is still rank-deficient (naming the features).
FitReport FitDriftModel(const std::vector<Run>& runs, const std::string& error_column,
                        const FitOptions& options);

}  // namespace whirl::drift
