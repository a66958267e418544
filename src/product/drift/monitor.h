#pragma once
// On-line check of a drift model with a check bar, and recalibration when it has gone stale
// (Liu, Hou, Li, Zhang, Wang and Mao, Xi'an University of Posts and Telecommunications, patent
// "Temperature compensation method, system and medium for CNC machine tools"). A model fitted
// once goes stale (ambient, ageing, process); the patent stops the machine at set intervals,
// measures a check bar at a fixed position, and when the measured error disagrees with the model
// E = sum k_i dT_i it re-fits the coefficients by least squares from a few new measurements.
// MonitorRun replays this on a logged run, so a shop can choose the interval and the threshold
// from its own data before touching the machine.
//
// Replay (what the control sees):
//   * temperatures arrive every sample; the model (mlr or dynamic: linear in its features
//     x = [1 f], model.h) predicts e_k = x_k' b every sample from the run's first row on (the lag
//     states and the reference run from there, as in PredictRun);
//   * the thermal error is known only at measurements: the run's error column at that sample plus
//     optional Gaussian noise N(0, noise_um^2) (one draw per sample, Rng(seed).Normal() of
//     core/random.h, the same on every standard library; every rule sees the same value at the
//     same sample);
//   * checks: the first at start + check_every, the next check_every after the last measurement
//     (the patent: "when the machining time reaches the set time"); each measurement (check or
//     refit) stops the machine stop_min_per_measurement [min]. The log cannot be paused: the stop
//     is counted as machine time, the samples go on as logged.
// Validity test (the patent's): the model is invalid at a check when
//   |measured - predicted| > threshold,
//   threshold = threshold_um when > 0, else threshold_sigma * sqrt(s^2 + noise_um^2),
//   s = model.residual_std_um (training residual std).
// Recalibration on an invalid check: m = refit_samples further measurements every refit_every,
// then the update from the n = m + 1 measurements (the invalid check and the m) with design rows
// x_j = [1 f_j] and values y_j; the new coefficients apply from the last measurement on. Rules:
//   patent   the patent's least-squares refit made rank-aware: the minimum change of the current
//            coefficients that fits the n measurements in the directions they identify:
//              Delta = S^-1 V_k diag(1/s_i) U_k' (y - X b),  X S^-1 = U diag(s) V' (S: 1 for the
//              intercept, each feature's training range), keeping the k directions with
//              s_i >= 0.05 s_max;
//            the other directions keep the current coefficients, and the event says how many of
//            the p + 1 were identified. With n >= p + 1 well-spread rows it is the patent's refit
//            (all coefficients by least squares on the n measurements alone); with fewer it no
//            longer extrapolates a fit of 4 coefficients to 4 points.
//   bayes    recursive least squares = Gaussian posterior with the current coefficients as the
//            prior mean and prior covariance P (first P0 = prior_scale * Cov(b) of the training
//            fit, regression.h), observation variance r = s^2 + noise_um^2:
//              P+ = (P^-1 + X'X / r)^-1,  b+ = b + P+ X' (y - X b) / r
//            (Bishop, PRML eqs. 3.50-3.51; the same as the gain form K = P X' (X P X' + r I)^-1,
//            b+ = b + K (y - X b), P+ = (I - K X) P of Kalman with no process noise, computed in
//            this information form for accuracy), and P+ is the prior of the next update. A very
//            weak prior (prior_scale -> inf) gives the patent's refit when X has full column rank
//            (tests/drift/test_monitor.cpp). Its change is bounded in closed form: b+ minimises
//            J(b) = (b - b)' P^-1 (b - b) + |y - X b|^2 / r, so J(b+) <= |y - X b|^2 / r and, for
//            every direction z, |z'(b+ - b)| <= sqrt(z' P z) |y - X b| / sqrt(r) (Cauchy-Schwarz).
//            The default rule. Cov(b) states the sampling error of the training fit, not how far
//            the machine may drift from it, and its shape is wrong for a drift: it is large only
//            where the training features were nearly collinear, so an update along it
//            extrapolates. With estimate_drift (default) each update first adds a drift
//            covariance, a random walk of the coefficients (Ljung and Soderstrom, "Theory and
//            Practice of Recursive Identification", 1983, ch. 6):
//              P <- P + q^2 D^-2,  D = diag(1, per feature the larger of its training range
//                                           and its range over the run's samples so far)
//            (a change of q um in the intercept or in each feature's contribution over the
//            range the control has seen, no direction preferred: a feature driven far outside
//            its training range is not made the cheapest to change), with q^2 estimated from
//            this run's checks by maximum likelihood of their misfits (empirical Bayes; Mehra,
//            "On the identification of variances and adaptive Kalman filtering", IEEE Trans.
//            Automatic Control 15, 1970): DriftVarianceMle over every check so far, valid ones included,
//            each check's misfit m_k ~ N(0, v_k + q^2 g_k), v_k = x_k' P x_k + r,
//            g_k = x_k' D^-2 x_k. q = 0 when the checks' misfits are what the noise and Cov(b)
//            explain: the update then barely moves. prior_scale 1 (Cov(b) as fitted).
//            Measured: random runs with persistent changes (tests/drift/test_monitor.cpp) 0.47 of
//            the static RMSE on average where prior scale 100 without the drift term gave 1.05;
//            FL_THERMAL (docs/drift.md): better on the validation block and the week.
//   offset   only the intercept: b0 += mean_j (y_j - x_j' b).
//   static   (reference) the model as fitted, never checked.
// Every check and update is logged (MonitorEvent) with the numbers it compared.
// Scores: MAE, RMSE, max of measured - predicted [um] over the scored rows: samples at or after
// `start` whose row index lies in [score_from, score_to) * samples; "none" is the measured error
// itself (no compensation). Machine time: stop_min = measurements * stop_min_per_measurement,
// stop share = stop_min / (monitored time + stop_min), monitored time = t_end - start.
// Output documents (CSV, JSON, text, HTML report): drift/monitor_report.h.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/run_file.h"
#include "drift/stream.h"

namespace whirl::drift {

enum class UpdateRule { kStatic, kPatent, kBayes, kOffset };
std::string ToString(UpdateRule r);                   ///< "static", "patent", "bayes", "offset"
UpdateRule ParseUpdateRule(const std::string& text);  ///< inverse; InputError otherwise

// Limits (resource and plausibility, stated in the messages).
inline constexpr int kMaxRefitSamples = 100;
inline constexpr int kMaxMonitorChecks = 100000;

struct MonitorOptions {
  /// Interval between checks [min; samples when the run has no time column] (> 0).
  /// Default 120 min: 3-4 checks in an 8-h shift. On a run without time the unit is samples and
  /// every output says so.
  double check_every = 120;
  /// Machine stop per check-bar measurement (a check or a refit measurement) [min] (>= 0).
  double stop_min_per_measurement = 1.0;
  /// Absolute validity threshold [um]; 0: use threshold_sigma.
  double threshold_um = 0;
  /// Threshold as a multiple of sqrt(s^2 + noise_um^2) when threshold_um is 0 (> 0).
  double threshold_sigma = 3;
  /// m: further measurements after an invalid check (0..kMaxRefitSamples; 0: the update uses
  /// the invalid check alone, no extra stop).
  int refit_samples = 0;
  /// Interval between the refit measurements [min; samples without time] (> 0).
  double refit_every = 5;
  /// Std of the check-bar measurement noise added to the logged error [um] (>= 0).
  double noise_um = 0;
  std::uint64_t seed = 1;  ///< noise draws
  /// bayes: prior covariance = prior_scale * the training fit's Cov(b) (> 0).
  double prior_scale = 1;
  /// bayes: add the drift covariance q^2 D^-2 estimated from the run's checks before each update
  /// (header comment); false: the prior is prior_scale * Cov(b) alone.
  bool estimate_drift = true;
  /// Monitoring starts here [min; samples]: no check before it, scores from it.
  double start = 0;
  double score_from = 0, score_to = 1;  ///< scored share of the run's rows, [from, to)
  ReferenceMode reference = ReferenceMode::kRunStart;
  /// Rules replayed besides static (always replayed).
  std::vector<UpdateRule> rules = {UpdateRule::kPatent, UpdateRule::kBayes, UpdateRule::kOffset};
  void Validate() const;  ///< InputError naming the option, value and rule
};

struct MonitorEvent {
  enum class Kind { kCheck, kRefitMeasurement, kUpdate, kSkipped };
  Kind kind = Kind::kCheck;
  int sample = 0;
  double time = 0;               ///< [min; samples]
  double measured_um = 0;        ///< measurement (checks, refit measurements)
  double predicted_um = 0;       ///< by the coefficients in force
  double threshold_um = 0;       ///< checks
  bool valid = true;             ///< checks: |measured - predicted| <= threshold
  Eigen::VectorXd coefficients;  ///< updates: after
  std::string message;           ///< reason and the numbers compared
};
std::string ToString(MonitorEvent::Kind k);  ///< "check", "refit-measurement", "update", "skipped"

struct StrategyResult {
  UpdateRule rule = UpdateRule::kStatic;
  Eigen::VectorXd predicted_um;  ///< per sample
  std::vector<MonitorEvent> events;
  int checks = 0, invalid_checks = 0, measurements = 0, recalibrations = 0;
  double stop_min = 0, stop_share = 0;
  ErrorStats score;  ///< measured - predicted over the scored rows
  Eigen::VectorXd final_coefficients;
  Eigen::MatrixXd final_covariance;  ///< bayes: the posterior covariance after the last update
};

/// A sensor-free baseline (a time-only or duty model fitted on the training runs) replayed as a
/// static model, never checked.
struct BaselineResult {
  std::string name;  ///< "time", "duty:<col>", ...
  Eigen::VectorXd predicted_um;
  ErrorStats score;
};

struct MonitorResult {
  std::string run, error_column, model_kind;
  /// Per-sample series (time, measured_um, measurement_noise_um, each strategy's and baseline's
  /// predicted_um): every sample for MonitorRun; empty for MonitorFile (its sink got them); the
  /// samples `rows_kept` names when thinned for a plot (PlotRows in drift/monitor_report.h).
  std::vector<double> time;
  std::vector<long long> rows_kept;        ///< empty: the series hold every sample
  bool time_from_index = false;
  Eigen::VectorXd measured_um;             ///< the logged error (without the added noise)
  Eigen::VectorXd measurement_noise_um;    ///< the draw added at each sample if measured
  long long samples = 0;                   ///< rows of the run
  double first_time = 0, last_time = 0;    ///< of the run [min; samples]
  double score_first_time = 0, score_last_time = 0;  ///< of the first and last scored row
  int score_begin = 0, score_end = 0;      ///< scored rows [begin, end)
  double monitored_min = 0;                ///< t_end - start [min; samples]
  double threshold_um = 0;                 ///< the threshold in force
  /// The model's training residual std (drift/model.h DriftModel::residual_std_um): the +-1 sd
  /// band of every rule's prediction in the report.
  double training_residual_std_um = 0;
  ErrorStats none;                         ///< no compensation over the scored rows
  std::vector<StrategyResult> strategies;  ///< static first, then options.rules
  std::vector<BaselineResult> baselines;   ///< sensor-free baselines (MonitorRun's argument)
  std::vector<std::string> warnings;
  /// The scored residuals' running sums per name ("none", each rule, each baseline), so days can
  /// be pooled without their samples (MonitorWeek).
  std::vector<std::pair<std::string, ErrorStatsAccumulator>> scored;
  /// The lowest scored MAE among none, the strategies and the baselines.
  std::string Strongest() const;
};

/// One sample of a replay as it is produced (MonitorFile's sink: the timeline writer, a plot's
/// decimation): the measured error on the model's zero without the noise, and each strategy's and
/// baseline's prediction [um], in the result's order.
struct MonitorSample {
  long long rows = 0;                   ///< of the run (its scan)
  double first_time = 0, last_time = 0;  ///< of the run
  long long index = 0;
  double time = 0;
  double measured_um = 0;
  std::vector<double> predicted_um;  ///< per strategy
  std::vector<double> baseline_um;   ///< per baseline
};
using MonitorSink = std::function<void(const MonitorSample&)>;

/// Replays `options` on `run` (which must have model.error_column). InputError for a network
/// model (not linear in coefficients), a missing column, a time-unit mismatch or bad options.
/// The errors are on the model's zero (DriftModel::zero), "none" and the baselines too.
/// `initial` (optional): coefficients and bayes covariance per rule to start from (a carried
/// model, MonitorWeek), in the order static, options.rules.
MonitorResult MonitorRun(const DriftModel& model, const Run& run, const MonitorOptions& options,
                         const std::vector<DriftModel>& baselines = {},
                         const std::vector<StrategyResult>* initial = nullptr);

/// The strategies a replay reports, in order: static, then options.rules without repeats.
std::vector<UpdateRule> ReplayedRules(const MonitorOptions& options);

/// A baseline model replayed beside the rules, with the name its row takes.
struct NamedBaseline {
  std::string name;
  DriftModel model;
};
/// MonitorRun on a run file streamed block by block (drift/stream.h): the same replay, events
/// and scores in fixed memory; the result's per-sample series stay empty and `sink` (optional)
/// receives every sample in order. Baselines by name ("time", "duty:<col>", "previous run").
MonitorResult MonitorFile(const DriftModel& model, const std::filesystem::path& run,
                          const MonitorOptions& options,
                          const std::vector<NamedBaseline>& baselines = {},
                          const std::vector<StrategyResult>* initial = nullptr,
                          const MonitorSink& sink = {}, const StreamProgress& progress = {});

/// A production week: the days replayed in order, each day's rules starting from the previous
/// day's final coefficients and bayes covariance (the static row stays the given model), the
/// check schedule from each day's start. Baselines per day: none, the given model (static),
/// "previous run" (drift/fit.h kPreviousRunBaseline): drift fit at its defaults redone on the
/// previous day (PreviousRunOptions, the definition drift report uses; the given model on the
/// first day), and
/// `time`: a time-only warm-up fitted on the previous day (on the first day: on
/// `first_time_training` when given, else none).
/// The week's rows: every name's statistics over the scored samples of the days it covers. Only
/// rows covering every day are ranked (`strongest`); a row covering fewer days (time without a
/// first-day fit) is compared, over its own days, with the rows that cover them all (`partial`).
struct WeekRow {
  std::string name;
  ErrorStats score;  ///< over the scored samples of the days it covers
  int days = 0;      ///< days covered
};
struct WeekPartial {
  std::string name;          ///< a row covering fewer days
  std::vector<int> days;     ///< their indices (0-based) in WeekResult::days
  double mae_um = 0;         ///< its MAE over them
  std::string strongest;     ///< the full row with the lowest MAE over the same days
  double strongest_mae_um = 0;
};
struct WeekResult {
  std::vector<MonitorResult> days;
  std::vector<WeekRow> week;      ///< none, static, the rules, the baselines
  std::vector<int> measurements;  ///< per strategy of days[0].strategies: over the week
  std::vector<double> stop_min;   ///< per strategy: total stop time [min; samples]
  std::string strongest;          ///< lowest week MAE among the rows covering every day
  std::vector<WeekPartial> partial;
};
/// Limits of one replay of days (MonitorWeek): at most kMaxMonitorDays files, and together at
/// most kMaxRunSamples samples (run_file.h), the bound of one run file; InputError otherwise.
inline constexpr int kMaxMonitorDays = 366;
/// InputError unless `count` day files are within kMaxMonitorDays (checked before reading them).
void CheckMonitorDays(std::size_t count);
WeekResult MonitorWeek(const DriftModel& model, const std::vector<Run>& days,
                       const MonitorOptions& options,
                       const std::vector<Run>& first_time_training = {});
/// MonitorWeek on day files streamed one at a time (MonitorFile per day; the previous day's refit
/// and time-only fit by FitFiles): memory independent of the days' lengths and count. `sink`
/// (optional) gets each day's samples with the day's index (0-based); the days' results keep no
/// per-sample series.
WeekResult MonitorWeekFiles(const DriftModel& model, const std::vector<std::filesystem::path>& days,
                            const MonitorOptions& options,
                            const std::function<void(std::size_t, const MonitorSample&)>& sink = {},
                            const StreamProgress& progress = {});

/// Features of every sample as the control computes them: samples x (1 + features), first
/// column 1 (the design rows of the updates).
Eigen::MatrixXd MonitorDesign(const DriftModel& model, const Run& run, ReferenceMode reference);

/// The update rules on n measurements (rows of x: [1 f], y: measured [um]); b: current
/// coefficients; prior_covariance (bayes, updated in place); noise_variance r [um^2].
/// patent (header comment): the rank-aware minimum change from b; *rank (optional): the number of
/// directions identified.
/// `column_scale` (size x.cols()): the unit of each column for the singular-value cut (the
/// replay passes 1 for the intercept and each feature's training range); empty: the columns'
/// norms over the n rows.
Eigen::VectorXd PatentRefit(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                            const Eigen::VectorXd& b, int* rank = nullptr,
                            const Eigen::VectorXd& column_scale = Eigen::VectorXd());
Eigen::VectorXd BayesUpdate(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                            const Eigen::VectorXd& b, Eigen::MatrixXd* prior_covariance,
                            double noise_variance);
/// One check's misfit for the drift estimate: m ~ N(0, variance + q^2 gain) [um, um^2].
struct Innovation {
  double misfit_um = 0, variance_um2 = 0, gain = 0;
};
/// q^2 >= 0 maximising sum_k log N(m_k; 0, v_k + q^2 g_k) [um^2 per squared unit of D]; 0 when
/// no k has g_k > 0 or the likelihood is largest at 0. One check: max(0, (m^2 - v) / g).
/// Log grid of 0.02 decades over [1e-6, 1e8] x min v_k / g_k, then golden section between the
/// neighbours of the best grid point.
double DriftVarianceMle(const std::vector<Innovation>& checks);
/// The unit of each coefficient for the patent's cut and the drift scale: 1 for the intercept,
/// then each feature's training range (1 when training saw a single value), so the directions
/// the patent keeps are those the measurements identify relative to the range the model was
/// fitted on, not to the few values at the measurements.
Eigen::VectorXd TrainingColumnScale(const DriftModel& m);
/// The box of design rows (intercept column included) the control has seen so far.
struct SeenBox {
  Eigen::VectorXd lo, hi;  // empty until the first row
  void Add(const Eigen::RowVectorXd& row);
};
/// D of the drift covariance: 1 for the intercept, per feature the larger of its column scale
/// (TrainingColumnScale) and its range in the box seen.
Eigen::VectorXd DriftScale(const Eigen::VectorXd& column_scale, const SeenBox& seen);
/// The check's record for DriftVarianceMle: misfit m = y - x b, variance x P x' + r, gain
/// x D^-2 x'.
Innovation CheckInnovation(const Eigen::RowVectorXd& x, double misfit_um,
                           const Eigen::MatrixXd& prior_covariance, double noise_variance,
                           const Eigen::VectorXd& drift_scale);
/// P += q^2 D^-2 with q^2 = DriftVarianceMle(checks); returns q^2.
double AddDriftVariance(const std::vector<Innovation>& checks, const Eigen::VectorXd& drift_scale,
                        Eigen::MatrixXd* prior_covariance);
Eigen::VectorXd OffsetUpdate(const Eigen::MatrixXd& x, const Eigen::VectorXd& y,
                             const Eigen::VectorXd& b);

}  // namespace whirl::drift
