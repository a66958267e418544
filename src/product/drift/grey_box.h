#pragma once
// The grey-box machine drift estimator: the 840D form of drift/joint.h with the physics of a
// screw-fed Z axis built in, fitted from the same shop measurements (drift/measurements.h):
//
//   K0(t)   = a' phi_o(t)                                                       [um]
//   G(t)    = g0 + g' phi_s(t) + g_b (B(t_0) - 20)                      [um per 1000 mm]
//   m_hat(t, z) = K0(t) + G(t) (z_ref - z) / 1000
//
// phi_o, phi_s: the offset sensors (head, bed) and the slope sensors (the screw's, the hall's)
// as ABSOLUTE temperatures referred to 20 degC, T - 20 [K], each with its first-order lags of
// the shared time constants (drift/model.h BuildFeatures' recursion, L_0 = u_0). The slope of a
// screw-fed axis is alpha_s (T_screw - 20) - alpha_w (T_blank(t_0) - 20) (Bryan 1990: only
// expansion against 20 degC matters), so a rise since power-on cannot carry it; the offset
// enters the lead error only through its change during a cut, where absolute and rise agree.
// g0: the slope intercept (what is left at 20 degC everywhere: a pitch error of the axis).
// B(t): the blank's temperature estimate, the first-order lag (blank_tau_min) of blank_sensor
// (the hall's air for stock stored in the hall); the control LATCHES it at the cut start t_0 and
// holds it for the whole cut (the blank was clamped at that temperature; the workpiece is
// measured at 20 degC). Only lead records see it (a probe or laser test cuts nothing): the
// column is 0 on every other reading.
// Fit: weighted least squares with one free constant per record (demeaned within each record,
// as drift/joint.h), and a ridge TOWARDS the physical coefficients (alpha x lengths, the caller's
// priors, spread equally over an input's static and lagged columns; g0 towards 0, g_b towards
// blank_prior) instead of towards 0:
//   min sum w (y - mu_r - x' b)^2 + lambda sum_j s_j^2 (b_j - p_j)^2,
// s_j the weighted RMS of column j, lambda = strength x sum w. A column no reading moves keeps
// its prior exactly; collinear sensors cannot trade large opposite coefficients (the penalty
// grows with the square of each departure from the prior). Weights: 1 / sigma^2 within a kind;
// the lead records together carry lead_share of the total weight (so hundreds of idle warm-up
// and laser readings cannot drown the cuts). Choices by the grouped cross-validated RMSE (leave
// one calendar day out, the same weights; or forward chaining on the leads, GreyValidation): the
// lags (greedy, at most max_lags from tau_grid), then the blank's time constant from
// blank_tau_grid, then the strength from strength_grid. The
// sensors are the caller's, physically placed (no greedy search among collinear sensors).
// Duty inputs (optional): control signals as logged (the day log's other columns, e.g. the ring
// drive's load on the offset, the Z speed on the slope), each with the same lags, appended after
// the temperatures of their channel (phi_o = [temperatures | duty], likewise phi_s), prior 0:
// the heat a source puts in now, which a sensor away from it sees only later.
#include <Eigen/Core>
#include <map>
#include <string>
#include <vector>

#include "drift/measurements.h"
#include "drift/run_file.h"

namespace whirl::drift {

struct GreyBoxSpec {
  std::vector<std::string> offset_sensors;  ///< K0 inputs (head, bed), as the logs name them
  std::vector<std::string> slope_sensors;   ///< slope inputs (screw, hall)
  std::string blank_sensor;                 ///< the blank's estimate; "" = no blank term
  /// Duty inputs of K0 and of the slope: other columns of the logs, as logged, prior 0.
  std::vector<std::string> offset_duty, slope_duty;
  double z_ref_mm = 6400;                   ///< slope reference (the Z screw's fixed bearing)
  /// Physical priors, um per K of an input (spread equally over its static and lagged
  /// columns); an input not named has prior 0. Offset: um per K; slope: um per 1000 mm per K.
  std::map<std::string, double> offset_prior, slope_prior;
  /// g_b's prior, um per 1000 mm per K: -alpha_w x 1e6 (steel: -11.5).
  double blank_prior = -11.5;
  /// Every sensor the spec reads: offset, slope, then the blank sensor (when set).
  std::vector<std::string> Inputs() const;
  /// The duty inputs it reads: offset_duty, then slope_duty.
  std::vector<std::string> DutyInputs() const;
};

/// How FitGreyBox scores a choice (lags, blank lag, strength):
///   kLeaveOneDayOut  the grouped CV RMSE over every record, one calendar day held out at a time;
///   kForwardLeads    forward chaining on the lead records: for each of the last forward_days
///                    days that hold a lead, fitted on the records of the days before it only,
///                    the weighted RMS of that day's lead residuals (what the shop's next screws
///                    see: a model trained on the past, scored on the leads of the day after).
///                    Only where the record holds at least 2 x forward_days days with a lead
///                    (each validation fit then has at least forward_days of them); a shorter
///                    history is scored by kLeaveOneDayOut.
enum class GreyValidation { kLeaveOneDayOut, kForwardLeads };

struct GreyBoxOptions {
  std::vector<double> tau_grid = {10, 20, 40, 80, 160, 320};  ///< min
  int max_lags = 2;                                           ///< 0..4
  std::vector<double> blank_tau_grid = {30, 60, 120, 240};    ///< min, each > 0
  std::vector<double> strength_grid = {1e-3, 1e-2, 1e-1, 1};  ///< each > 0
  /// The lead records' share of the total weight, in (0, 1): 0.9 since issue 41's eighth round
  /// (docs/machine-history.md; the leads are what a cut's error is; 0.5 before).
  double lead_share = 0.9;
  GreyValidation validation = GreyValidation::kLeaveOneDayOut;
  int forward_days = 10;    ///< kForwardLeads: validation days, 2..100
  /// false: the channel's temperatures enter through their lags only (each input's prior spread
  /// over its lagged columns, the instant column's coefficient 0): no body whose growth makes the
  /// error follows a reading at once, and the instant column carries the reading's noise into
  /// the compensation. With no lag chosen the instant columns stay. Duty inputs are not affected.
  bool instant_offset_inputs = true, instant_slope_inputs = true;
  /// On a record with fewer than 2 x forward_days lead days (LeadDays; whatever the
  /// validation), the strength is chosen from this grid instead of strength_grid (each > 0);
  /// empty: strength_grid on every record. {1}: the physics weighs as much as the data where 5
  /// held-out days cannot choose (issue 41's twelfth round, docs/machine-history.md).
  std::vector<double> short_record_strength_grid;
  /// On a record with fewer than 2 x forward_days lead days: the offset sensors keep their
  /// instant column and only the first this many of the chosen lags (the shortest); the others'
  /// columns are 0 with a prior of 0, so their coefficients are exactly 0 and the evaluator and
  /// the 840D programs run the model as it is. -1: every chosen lag (off), else 0..4. Duty
  /// inputs and the slope channel are not affected. 0: the offset as read (issue 41's thirteenth
  /// round, docs/machine-history.md: on 5 lead days lags of the slow bed bend K0 along a cut).
  int short_record_offset_lags = -1;
  void Validate() const;    ///< InputError naming the field and the rule
};

struct GreyBoxModel {
  std::vector<std::string> offset_sensors, slope_sensors;
  std::string blank_sensor;
  std::vector<std::string> offset_duty, slope_duty;  ///< as logged (other columns), after the sensors
  std::vector<double> time_constants;  ///< min, ascending
  double z_ref_mm = 6400;
  /// Per offset feature (input-major: each sensor's T - 20, then its lags; then each duty
  /// input as logged and its lags), um per K (um per unit of a duty input).
  Eigen::VectorXd a;
  Eigen::VectorXd g;  ///< per slope feature (the same order), um per 1000 mm per K (per unit)
  double slope_intercept_um_per_1000 = 0;  ///< g0
  double blank_tau_min = 60;               ///< B's lag
  double blank_um_per_1000_per_k = 0;      ///< g_b
  double prior_strength = 0;               ///< the chosen strength
  double cv_rmse_um = 0;  ///< validation RMSE of the final choice (GreyBoxOptions::validation)
  int rows = 0;
  /// Training range of each feature over the record's day logs, as GreyBoxEvaluator runs them
  /// from each log's first row (SetGreyBoxRanges): phi_o and phi_s [K against 20 degC] and B
  /// [degC]. The drift action's slope bound (interp/drift_action.h) reads them.
  Eigen::VectorXd offset_min, offset_max, slope_min, slope_max;
  double blank_min_c = 20, blank_max_c = 20;
  std::vector<std::string> notes;  ///< provenance (the command line, the records)
  /// The temperatures a control feeds the evaluator, in order: offset sensors, slope sensors,
  /// then the blank sensor (when set).
  std::vector<std::string> Inputs() const;
  /// The duty inputs it feeds after them: offset_duty, then slope_duty.
  std::vector<std::string> DutyInputs() const;
};

/// The calendar days that hold a lead reading (a lead record with a row), ascending.
std::vector<int> LeadDays(const ShopRecord& record);
/// Whether `record` holds at least 2 x forward_days lead days (LeadDays): long enough for
/// forward chaining, and where short_record_strength_grid and short_record_offset_lags no
/// longer apply.
bool LongRecord(const ShopRecord& record, const GreyBoxOptions& options);
/// Whether FitGreyBox scores its choices by forward chaining on `record`: kForwardLeads and a
/// LongRecord; else leave one day out.
bool ScoresForward(const ShopRecord& record, const GreyBoxOptions& options);
/// The strengths FitGreyBox chooses from on `record`: short_record_strength_grid when it is set
/// and the record holds fewer than 2 x forward_days lead days, else strength_grid.
const std::vector<double>& StrengthGrid(const ShopRecord& record, const GreyBoxOptions& options);

/// InputError: an invalid record, a missing column, no sensor, bad options, or fewer readings
/// than unknowns.
GreyBoxModel FitGreyBox(const ShopRecord& record, const GreyBoxSpec& spec,
                        const GreyBoxOptions& options = {});

/// Sets the model's training ranges from `logs` (each run from its first row); a model without
/// a log keeps ranges of zero width at 0 K (B at 20 degC).
void SetGreyBoxRanges(GreyBoxModel* m, const std::vector<Run>& logs);

/// m_hat of every row of a record (its own day log from its first row); a lead record latches
/// B at its first reading (the cut start).
std::vector<double> PredictGreyRecord(const GreyBoxModel& m, const ShopRecord& record,
                                      const MeasurementRecord& r);

/// The model sample by sample as the control runs it from power-on: K0, the slope without the
/// blank term, and B (the blank estimate now, degC). At the cut start the control latches B;
/// the slope of the cut is then slope_um_per_1000 + BlankSlope(latched B).
class GreyBoxEvaluator {
 public:
  explicit GreyBoxEvaluator(const GreyBoxModel& model);
  struct Output {
    double k0_um = 0, slope_um_per_1000 = 0, blank_c = 20;
  };
  Output Step(double time_min, const Eigen::VectorXd& raw_inputs);
  /// g_b (B_latched - 20), um per 1000 mm.
  double BlankSlope(double latched_blank_c) const;

 private:
  const GreyBoxModel* model_;
  Eigen::VectorXd lag_;
  double blank_ = 20, last_time_ = 0;
  bool started_ = false;
};

/// Raw inputs of every sample of a run: Inputs() (temperatures, degC), then DutyInputs() (as
/// logged); InputError if one is missing.
Eigen::MatrixXd GreyBoxRawInputs(const GreyBoxModel& m, const Run& run);

/// Features of `sensors` on a run as absolute temperatures referred to 20 degC, input-major
/// with their lags (samples x sensors (1 + taus)).
Eigen::MatrixXd AbsoluteFeatures(const Run& run, const std::vector<std::string>& sensors,
                                 const std::vector<double>& taus);

/// One channel's features: AbsoluteFeatures of `sensors`, then `duty` as logged with the same
/// lags (samples x (sensors + duty)(1 + taus)).
Eigen::MatrixXd GreyChannelFeatures(const Run& run, const std::vector<std::string>& sensors,
                                    const std::vector<std::string>& duty,
                                    const std::vector<double>& taus);

}  // namespace whirl::drift
