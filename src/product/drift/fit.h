#pragma once
// Fitting the drift models of drift/model.h on training runs: the choice of sensors (the fuzzy
// clustering and grey relational grades of Miao, Gao, Dang and Miao, "Analysis of the thermal
// error characteristics of CNC machine tools", Hefei University of Technology: drift/selection.h;
// or a class count by cross-validation), the lag search of the dynamic kind (greedy forward
// selection of time constants from FitOptions::tau_grid on the cross-validated RMSE) and the
// network kind's Bayesian-regularized training (nn/trainbr.h). drift/model.h says what each kind
// computes; this header, how it is fitted.
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "drift/model.h"
#include "drift/run_file.h"
#include "drift/selection.h"
#include "nn/trainbr.h"

namespace whirl::drift {

/// The model families `drift fit` scores by validation on the training runs (FitDriftModel):
///   sensors       the selected sensors (and extra inputs), kind mlr / dynamic / network;
///   time          time-only first-order warm-up, 1 or 2 terms (time1, time2; model.h header);
///   sensors+time  the selected sensors plus one elapsed-time term (only with >= 3 training runs:
///                 with fewer, the validation favours it and it extrapolates badly);
///   auto          all of them (linear kinds; a network, or sensors given by name, fit
///                 `sensors` only).
///   time1, time2  one of the time-only models alone.
enum class Candidates { kAuto, kSensors, kTime, kSensorsTime, kTime1, kTime2 };
/// "auto", "sensors", "time", "sensors+time", "time1", "time2"
std::string ToString(Candidates c);
Candidates ParseCandidates(const std::string& text);  ///< inverse; InputError otherwise

/// How FitDriftModel chooses among the scored candidates (ChooseCandidate).
struct ChoiceRule {
  /// Within (1 + tolerance) x the lowest validation RMSE, the fewest parameters win.
  double tolerance = 0.05;
  /// A sensor-free candidate replaces the sensor model only with a validation RMSE at most
  /// (1 - margin) x the sensor model's ...
  double margin = 0.2;
  /// ... and a lower RMSE in at least this share of the folds both were fitted in (3 of 4
  /// forward-chaining folds; with 2 or 3 runs left out one at a time, every run).
  double consistency = 0.75;
  void Validate() const;
};

struct FitOptions {
  ModelKind kind = ModelKind::kMlr;
  /// Zero of the training errors, stored in the model (run_file.h ErrorZero).
  ZeroConvention zero;
  Candidates candidates = Candidates::kAuto;
  ChoiceRule choice;                 ///< among the candidates (ChooseCandidate)
  /// Candidates auto with the mlr kind and the selection (no sensors given): the model written is
  /// (1 - dynamic_share) x the mlr kind's choice + dynamic_share x the dynamic kind's choice (the
  /// same candidates scored with lagged sensors; BlendModels), one linear model on the union of
  /// their features: the lagged model shrunk towards the static one. 0: the mlr choice alone.
  /// 0.25 was chosen on issue 38's second-round tuning set (docs/drift.md).
  double dynamic_share = 0.25;
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
  /// Set by FitFiles (drift/stream.h) when the runs are an evenly thinned sample of longer logs:
  /// the logs' own sampling step [min, or samples] (the warm-up's shortest time constant is 2 of
  /// it; NaN: the runs' median step), and the rises' moments over every row of the logs (the
  /// selection's screen, similarity and F test; null: from the runs).
  double sampling_step = std::numeric_limits<double>::quiet_NaN();
  std::shared_ptr<const SelectionMoments> all_rows;
  void Validate() const;
};

struct LagSearchStep {
  std::vector<double> time_constants;
  double cv_rmse_um = 0;
};

/// One candidate of FitDriftModel's validation: its validation RMSE (pooled over the folds of the
/// lag search: leave one run out with several runs, else blocks of the one run).
struct CandidateScore {
  std::string name;                    ///< "sensors", "time1", "time2", "sensors+time"
  std::vector<double> time_constants;  ///< elapsed-time constants fitted on all runs
  int parameters = 0;                  ///< coefficients incl. intercept and time constants
  double cv_rmse_um = std::numeric_limits<double>::infinity();  ///< +inf: not validated
  int folds = 0;
  std::vector<double> fold_rmse_um;  ///< per fold, in fold order; NaN: too few rows to fit there
  bool sensor_free = false;          ///< time1, time2
};

/// The candidate chosen (index into the scores) and why, with the numbers compared.
struct CandidateChoice {
  std::size_t pick = 0;
  std::string why;
};
/// The rule: among the validated candidates (finite RMSE), the fewest parameters within
/// (1 + tolerance) of the lowest RMSE (ties: the lower RMSE). When that is sensor-free and the
/// sensor model ("sensors") was validated, it replaces the sensor model only when it wins clearly
/// (RMSE <= (1 - margin) x the sensors') and consistently (lower in >= consistency of the folds
/// both were fitted in); otherwise the sensor model stays. InputError when none was validated.
CandidateChoice ChooseCandidate(const std::vector<CandidateScore>& scores,
                                const ChoiceRule& rule = {});

struct FitReport {
  DriftModel model;
  std::vector<CandidateScore> candidates;  ///< scored candidates (empty: one family asked for)
  std::string chosen;                      ///< the candidate fitted and why
  /// A blend (FitOptions::dynamic_share): its coefficients come from the search's runs (FitFiles
  /// does not refit it on every row of thinned logs).
  bool blended = false;
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
/// The errors are first put on options.zero (a fixed zero without a level takes the first row of
/// the first run), which the model stores. With several candidates (options.candidates), each is
/// scored by the validation RMSE with its whole fit (selection excepted, as the class-count
/// choice) redone in every fold, per fold and pooled; options.choice picks one (ChooseCandidate:
/// the fewest parameters within 5 % of the lowest RMSE, a time model replacing the sensors only
/// when it wins clearly and consistently), and FitReport::chosen says why with the numbers.
/// Dead and duplicate sensors (selection.h convention 8) are left out of the selection and of
/// given sensors, with a warning each (FitReport::warnings); InputError naming the run files when
/// no sensor is left, or when the regression is still rank-deficient (naming the features).
FitReport FitDriftModel(const std::vector<Run>& runs, const std::string& error_column,
                        const FitOptions& options);

/// (1 - share) x a + share x b as one linear model (kind mlr or dynamic) of a's error column: the
/// union of the two models' sensors, extra inputs, lag and elapsed-time constants, each feature's
/// coefficient the blend of the two (0 where a model lacks the feature), so its prediction is
/// the blend of the two predictions sample by sample. On `runs` (the training runs, on the
/// models' error zero): the feature ranges, residual std (n - p - 1 degrees of freedom), R^2 and
/// VIF; the coefficient covariance is (1 - share) Cov_a + share Cov_b (both embedded in the
/// union), an upper bound of the blend's whatever the two fits' correlation (the square of a
/// convex combination of standard deviations is at most the combination of the variances).
/// InputError unless both are linear kinds of the same error column, time unit and error zero,
/// and 0 <= share <= 1.
DriftModel BlendModels(const DriftModel& a, const DriftModel& b, double share,
                       const std::vector<Run>& runs);

/// The name of the "previous run" baseline in drift report and drift monitor --day.
inline constexpr const char* kPreviousRunBaseline = "previous run";

/// The "previous run" baseline, one definition for every command: `drift fit` at its defaults
/// redone on the run before (the previous run shown by drift report, the previous day of drift
/// monitor --day), what a shop gets by refitting each day: candidates auto, Miao et al.'s
/// selection afresh (the model's own sensors when they were given), the model's kind (a network:
/// mlr), extra inputs and error zero; one thread.
FitOptions PreviousRunOptions(const DriftModel& model);

}  // namespace whirl::drift
