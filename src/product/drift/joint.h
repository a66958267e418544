#pragma once
// One estimator for every machine drift model, fitted only from shop measurements
// (drift/measurements.h), in the form a SINUMERIK 840D applies (SD43900 offset K0 and SD43910
// slope about the reference position, Siemens 840D Function Manual Extended Functions, K3):
//
//   m_hat(t, z) = a' phi(t) + g' phi(t) (z_ref - z) / 1000        [um]
//
// phi(t) = the features of the model's inputs on the day log (drift/model.h BuildFeatures: each
// input as a rise since the log's first row, i.e. since power-on, and its first-order lags with
// the shared time constants); z_ref = the Z screw's fixed bearing (or a linear scale's datum).
// The families differ only in their inputs: sensor temperatures (`_C` columns), or the control's
// own signals (`other` columns: a warm-up clock is the lag of `power_on`; a schedule rule the lags
// of ring_on, ring_load_pct, cutting, ...). Fit: weighted least squares with one free constant
// per record,
//   min sum_r sum_k w_rk (y_rk - mu_r - a' phi_rk - g' psi_rk)^2,  psi = phi (z_ref - z) / 1000,
// solved by weighted demeaning within each record (no record needs a zero or a reference
// temperature), w = 1 / sigma^2. A slope direction that no record identifies (its psi column lies
// in the span of the phi columns after demeaning, e.g. every reading at one z), or whose feature
// the readings that see the slope do not cover (JointFitOptions::slope_coverage), is left out
// (g = 0) and reported. A ridge of 1e-8 x trace / p on the standardized columns keeps the solve
// safe.
// Control signals enter through their lags only (their static step column is left out when a
// lag is chosen). Lags: greedy forward choice of at most max_lags shared time constants from
// tau_grid, accepted while the grouped cross-validated RMSE (leave one calendar day out; a
// held-out record is scored after removing its own weighted mean) falls. Sensor family: greedy forward choice of at most
// max_sensors sensors by the same cross-validation (static features), before the lags.
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "drift/measurements.h"
#include "drift/model.h"

namespace whirl::drift {

struct JointSpec {
  std::vector<std::string> sensors;       ///< temperature columns (without _C) used as given
  std::vector<std::string> sensor_pool;   ///< non-empty: choose sensors from these by CV
  std::vector<std::string> other_inputs;  ///< control signals (other columns), as logged
  /// Time constants [min] taken as chosen before any search (sensors are then chosen with these
  /// lags; the lag search adds more only up to max_lags).
  std::vector<double> time_constants;
  double z_ref_mm = 6400;                 ///< reference position of the slope, mm
};

struct JointFitOptions {
  std::vector<double> tau_grid = {5, 10, 20, 40, 80, 160, 320};  ///< min
  int max_lags = 2;     ///< 0..4
  int max_sensors = 3;  ///< sensor pool: at most this many (1..13)
  /// false: static only when the lag search rejects every lag; true: at least one lag (inputs
  /// that are steps, such as power_on, carry no information without one).
  bool require_lag = false;
  /// A slope coefficient g_j is estimated only where the readings that see the slope (day logs
  /// with readings >= 1000 mm apart along Z: laser targets, leads) cover the feature's range:
  /// max |phi_j| over them >= slope_coverage x max |phi_j| over all readings; otherwise g_j = 0
  /// and it is reported unidentified (no extrapolation from idle laser tests to cutting rises).
  double slope_coverage = 0.5;
};

struct JointDriftModel {
  std::vector<std::string> sensors, other_inputs;
  std::vector<double> time_constants;  ///< min, ascending
  double z_ref_mm = 6400;
  Eigen::VectorXd a, g;               ///< um per feature unit, BuildFeatures order
  std::vector<bool> slope_identified;  ///< per feature: g estimated (false: g = 0)
  Eigen::MatrixXd covariance;          ///< of [a; g], um^2 / unit^2 (sigma-weighted)
  double cv_rmse_um = 0;               ///< grouped CV RMSE of the final choice
  int rows = 0;                        ///< readings used
  int features() const { return static_cast<int>(a.size()); }
};

struct JointFitReport {
  JointDriftModel model;
  std::vector<std::pair<std::string, double>> search;  ///< accepted steps and their CV RMSE
  std::vector<std::string> notes;                      ///< unidentified slopes, dropped sensors
};

/// InputError: an invalid record (ShopRecord::Validate), a missing column, fewer readings than
/// unknowns, or no calendar day to hold out when a search is asked for.
JointFitReport FitJoint(const ShopRecord& record, const JointSpec& spec,
                        const JointFitOptions& options = {});

/// m_hat of every row of a record (its own day log, features from the log's first row), um.
std::vector<double> PredictRecord(const JointDriftModel& m, const ShopRecord& record,
                                  const MeasurementRecord& r);

/// The model sample by sample as a control runs it: K0 = a' phi and the slope per 1000 mm
/// G = g' phi from one sample's raw inputs (sensor temperatures [degC] then other inputs); the
/// first Step is the day's power-on (rises start there, lags start at their input).
class JointEvaluator {
 public:
  explicit JointEvaluator(const JointDriftModel& model);
  struct Output {
    double k0_um = 0, slope_um_per_1000 = 0;
    double At(double z_mm, double z_ref_mm) const { return k0_um + slope_um_per_1000 * (z_ref_mm - z_mm) / 1000; }
  };
  Output Step(double time_min, const Eigen::VectorXd& raw_inputs);

 private:
  const JointDriftModel* model_;
  Eigen::VectorXd reference_, lag_;
  double last_time_ = 0;
  bool started_ = false;
};

/// Raw inputs of the model (sensor temperatures, other inputs) of every sample of a run.
Eigen::MatrixXd JointRawInputs(const JointDriftModel& m, const Run& run);

/// The offset (K0) and slope (per 1000 mm) channels as two dynamic drift models (drift/model.h),
/// for the 840D synchronized action (interp/drift_action.h). The intercepts are 0.
std::pair<DriftModel, DriftModel> ToDriftModels(const JointDriftModel& m);

}  // namespace whirl::drift
