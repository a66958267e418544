#pragma once
// Drift models: the thermal error of one channel [um] from temperature rises on chosen sensors.
//
// Inputs u_i (in this order): the rises of `sensors`, dT_s = T_s - T_ref,s [K], then the
// `extra_inputs` as logged (e.g. spindle_rpm, their own unit). T_ref is the run's first row
// (ReferenceMode::kRunStart, Miao et al.'s convention and the default; training always uses it) or
// the model's reference_C (kModel: the mean first row of the training runs, for a control that
// cannot know when a run started).
// Features (regressors), input-major: for each input its value and its first-order-lagged copies
//   L_tau(u)_k = L_{k-1} + (1 - exp(-(t_k - t_{k-1}) / tau)) (u_k - L_{k-1}),  L_0 = u_0,
// one per time constant in `time_constants` (shared by all inputs; unit: min, or samples when the
// training runs had no time column). Deformation lags temperature; a control evaluates the same
// recursion every interpolation cycle with a = 1 - exp(-T_cycle / tau) (interp/drift_action.h).
// Elapsed time (a sensor-free input): the virtual input "elapsed" is 0 at the run's first row and
// 1 afterwards (a unit step at the run start); its features are its first-order lags with
// L_0 = 0, one per time constant in `elapsed_time_constants`:
//   elapsed_lag<tau>(t) = 1 - exp(-(t - t_0) / tau)   (exact: the step is piecewise constant),
// so a model on them alone is the first-order warm-up e = b0 + sum_j A_j (1 - exp(-(t - t0)/tau_j))
// (the time-only baseline and candidate, FitWarmUp in drift/regression.h). They follow the
// input-major features. A control evaluates them with the same recursion from the run start
// (interp/drift_action.h). Fitted, every tau_j lies within what the training runs identify (at
// most the longest run's t - t0, at least two sample intervals) and the gains A_j share one sign:
// after the trained time range the warm-up goes on towards its plateau b0 + sum_j A_j and never
// passes it; the predictor counts those samples and says so (TrainedElapsed, WarmUpPlateau).
// Kinds:
//   mlr      Miao et al.'s multiple linear regression, no lags: e = b0 + sum_s b_s dT_s.
//   dynamic  the same regression on the features with lags; the time constants are picked from
//            FitOptions::tau_grid by greedy forward selection on the cross-validated RMSE (folds:
//            leave one run out with several runs, else `folds` contiguous blocks of the one run,
//            forward-chaining by default); a lag is added only while it lowers that RMSE.
//   network  the project's Bayesian-regularized k-h-1 network (nn/trainbr.h, mapminmax scaling)
//            on the same inputs without lags; its standard deviation is MacKay's error bar
//            sigma^2 = 1 / (2 beta) + g' A^-1 g (nn/model.h), in um.
// Linear kinds give a standard deviation sqrt(s^2 + x1' Cov(b) x1), x1 = [1 features].
// The training range of every feature is stored; the predictor counts samples outside it and
// warns (a linear model extrapolates linearly, a network saturates).
// Fitting (sensor selection, lag search, training): drift/fit.h.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "drift/regression.h"
#include "drift/run_file.h"
#include "nn/network.h"

namespace whirl::drift {

enum class ModelKind { kMlr, kDynamic, kNetwork };
std::string ToString(ModelKind k);                  ///< "mlr", "dynamic", "network"
ModelKind ParseModelKind(const std::string& text);  ///< inverse; InputError otherwise

enum class ReferenceMode { kRunStart, kModel };
std::string ToString(ReferenceMode m);  ///< "run-start", "model"
ReferenceMode ParseReferenceMode(const std::string& text);

/// One regressor: an input or its lagged copy.
struct Feature {
  std::string input;  ///< the column, e.g. "t3_C" or "spindle_rpm"
  double tau = 0;     ///< lag time constant (model time unit); 0: the input itself
  std::string Name(const std::string& time_unit) const;  ///< "t3_C" or "t3_C_lag40min"
};

/// Largest training residual std a model may state, um (10 x the error range of a run file,
/// kMaxAbsErrorUm): a larger one is a corrupt file and would make every threshold infinite.
inline constexpr double kMaxResidualStdUm = 10 * kMaxAbsErrorUm;
/// Longest lag time constant, in the model's time unit (FitOptions::tau_grid's limit).
inline constexpr double kMaxTimeConstant = 1e6;

struct DriftModel {
  /// 2: error_zero, gauge_level_um and elapsed_time_constants; schema 1 files are read with
  /// error zero as-logged (run_file.h) and no elapsed features.
  static constexpr int kSchemaVersion = 2;
  static constexpr const char* kFormat = "whirl-drift-model";

  ModelKind kind = ModelKind::kMlr;
  std::string error_column;                  ///< predicted channel, e.g. "ch1_um" [um]
  std::vector<std::string> sensors;          ///< temperature columns used (rises) [degC -> K]
  Eigen::VectorXd reference_C;               ///< per sensor: mean first row of the training runs
  std::vector<std::string> extra_inputs;     ///< other columns used as logged
  std::string time_unit = "min";             ///< "min", or "sample" (training runs had no time)
  std::vector<double> time_constants;        ///< lag time constants [time_unit], ascending
  /// Time constants of the elapsed-time features [time_unit] (header comment); may be the only
  /// features (a time-only model, no sensor).
  std::vector<double> elapsed_time_constants;
  std::vector<Feature> features;             ///< input-major, then the elapsed lags
  /// The zero of the errors the model was fitted on and is evaluated against (run_file.h).
  ZeroConvention zero;
  Eigen::VectorXd feature_min, feature_max;  ///< training range per feature

  LinearFit linear;  ///< mlr, dynamic: coefficients b0 [um], then um per feature unit

  nn::Network network;                   ///< network: k-h-1 in the normalized space
  nn::MapMinMax input_scaling;           ///< network: mapminmax of the features
  nn::MapMinMax target_scaling;          ///< network: mapminmax of the error
  Eigen::MatrixXd posterior_covariance;  ///< network: A^-1 (nn/trainbr.h)
  double noise_variance = 0;             ///< network: 1 / (2 beta), normalized units

  double residual_std_um = 0;  ///< training residual std (all kinds), [0, kMaxResidualStdUm]
  double r_squared = 0;        ///< training R^2 (all kinds), at most 1
  std::vector<std::string> training_runs;
  RunState state = RunState::kUnknown;  ///< common state of the training runs, else unknown
  int training_samples = 0;
  std::string selection;           ///< how the sensors were chosen (selection message or "given")
  std::vector<std::string> notes;  ///< provenance (command line, lag search)

  int InputCount() const { return static_cast<int>(sensors.size() + extra_inputs.size()); }
  /// True when the model uses no temperature sensor (time-only or duty baselines).
  bool SensorFree() const { return sensors.empty(); }
  /// Throws InputError naming the field when sizes are inconsistent or a value is outside its
  /// range (residual_std_um, r_squared, time constants, noise variance).
  void Validate() const;
};
void to_json(nlohmann::json& j, const DriftModel& m);
void from_json(const nlohmann::json& j, DriftModel& m);
DriftModel ReadDriftModel(const std::filesystem::path& path);
void WriteDriftModel(const std::filesystem::path& path, const DriftModel& m);

/// The model evaluated sample by sample, as a control would: Step() takes one sample's raw
/// temperatures of model.sensors [degC] followed by the extra inputs, updates the lag states and
/// returns the predicted error [um]. The first Step initializes the lags (L_0 = u_0).
class DriftEvaluator {
 public:
  DriftEvaluator(const DriftModel& model, const Eigen::VectorXd& reference_C);
  double Step(double time, const Eigen::VectorXd& raw_inputs);
  const Eigen::VectorXd& features() const { return features_; }  ///< of the last Step
  /// Standard deviation of the last prediction [um] (see the header comment).
  double StdDev() const;

 private:
  const DriftModel* model_;
  Eigen::VectorXd reference_;
  Eigen::VectorXd features_;
  double last_time_ = 0;
  bool started_ = false;
};

/// Raw inputs (sensors' temperatures, extras) of every sample of a run: samples x inputs.
/// InputError if the run lacks a column the model needs.
Eigen::MatrixXd RawInputs(const DriftModel& model, const Run& run);
/// Feature matrix (samples x features) of a run with the run's first row as reference; the
/// elapsed-time features (header comment) last.
Eigen::MatrixXd BuildFeatures(const Run& run, const std::vector<std::string>& sensors,
                              const std::vector<std::string>& extra_inputs,
                              const std::vector<double>& time_constants,
                              const std::vector<double>& elapsed_time_constants = {});
/// The elapsed-time features of a run: samples x taus, column j = 1 - exp(-(t - t0) / tau_j).
Eigen::MatrixXd ElapsedFeatures(const std::vector<double>& t, const std::vector<double>& taus);

/// PredictRun one sample at a time, for a run streamed from its file (the same evaluator, checks
/// and warnings): Step takes a sample's time and raw inputs (model.sensors' temperatures [degC],
/// then the extra inputs as logged) and returns the predicted error [um]; the first Step sets the
/// run-start reference. Counts the samples outside the training range and beyond the trained time.
class RunPredictor {
 public:
  /// InputError when the run's time axis (`time_from_index`) does not match the model's unit.
  RunPredictor(const DriftModel& model, bool time_from_index, const std::string& source,
               ReferenceMode reference = ReferenceMode::kRunStart);
  double Step(double time, const Eigen::VectorXd& raw_inputs);
  double StdDev() const { return evaluator_->StdDev(); }  ///< of the last Step [um]
  long long outside_range_samples() const { return outside_; }
  long long beyond_trained_time_samples() const { return beyond_; }
  /// PredictRun's warnings for a run named `run` of `samples` samples (the error-zero warning
  /// only when `has_measured`).
  std::vector<std::string> Warnings(const std::string& run, long long samples,
                                    bool has_measured) const;

 private:
  const DriftModel* model_;
  bool time_from_index_;
  ReferenceMode reference_;
  std::unique_ptr<DriftEvaluator> evaluator_;
  Eigen::Index input_features_ = 0;
  double trained_ = 0, first_time_ = 0;
  long long outside_ = 0, beyond_ = 0;
};

/// The columns of the model's raw inputs in a run's groups: model.sensors in the temperatures,
/// the extra inputs in the other columns (InputError naming a missing one).
struct InputColumns {
  std::vector<int> sensors, extras;
};
InputColumns ModelInputColumns(const DriftModel& model, const std::vector<std::string>& sensor_names,
                               const std::vector<std::string>& other_names,
                               const std::string& source);

struct RunPrediction {
  std::string run;
  std::vector<double> time;  ///< run.time_min (samples when time_from_index)
  bool time_from_index = false;
  Eigen::VectorXd predicted_um;  ///< the compensation value is its negative
  Eigen::VectorXd std_um;        ///< standard deviation of each prediction
  bool has_measured = false;     ///< the run has the model's error column
  Eigen::VectorXd measured_um;
  int outside_range_samples = 0;  ///< samples with an input feature outside its training range
  /// Samples later after the run's start than the longest training run (elapsed-time models).
  int beyond_trained_time_samples = 0;
  std::vector<std::string> warnings;
};
RunPrediction PredictRun(const DriftModel& model, const Run& run,
                         ReferenceMode reference = ReferenceMode::kRunStart);

/// The trained time range of a model with elapsed-time features: the longest training run's time
/// since its start [time_unit], from the features' training maxima (x = 1 - exp(-T / tau)); +inf
/// without elapsed features or where x reached 1 in double (T > 37 tau: the plateau was reached).
double TrainedElapsed(const DriftModel& model);
/// The level the elapsed-time warm-up approaches [um]: b0 + sum A_j for a time-only model, sum A_j
/// (its warm-up part) beside sensors; 0 without elapsed features. The gains share one sign
/// (drift/regression.h FitWarmUp), so the warm-up is monotone and never passes it.
double WarmUpPlateau(const DriftModel& model);

}  // namespace whirl::drift
