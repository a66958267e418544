#pragma once
// The ceiling of the machine half (`whirl machine ceiling`, issue 41): what a regression on the
// control's signals could reach if it were trained on the machine's EXACT truth, per scenario,
// beside the shop's estimators trained on what the shop measures. Simulator figures only.
//
// Per machine of a scenario (machine/scenarios.h BuildMachineWorld, the calendar's past_days
// production days before the test window): every past cut gives training rows, one per
// row_step_min along the cut, target the machine's true error m(t, z(t)) along the cut
// (machine/truth.h TrueCutError: head, Z axis and the blank cut warm), inputs the control log at
// the latest control sample at or before t (machine/instruments.h ControlLog averaged as the
// evaluation's control does, FieldProtocol::sensor_average_min). The model is the 840D form
//   m_hat(t, z) = a' [1, x(t)] + (g' [1, x(t)] + g_b (B - 20)) (z_ref - z) / 1000,
// fitted by least squares to m along each training cut against the cut's first row (a lead holds
// only what changes along its cut; the level at the cut start drops out, and with it a(0)), with a
// ridge of 1e-8 on unit-norm columns except the intercepts (solved by QR), x one of the sets:
//   none        no feature (the intercepts only)
//   time        first-order lags (20, 80, 320 min) of power_on (time since power-on)
//   time+duty   + the same lags of ring_on, cutting, ring_load_pct, z_speed_mm_min
//   joint       drift/joint's features: every sensor's rise since power-on and its lags 20, 80
//   absolute    every sensor's absolute temperature - 20 and its lags 20, 80, + time+duty
//   +blank      absolute + the blank's TRUE temperature at the cut start (B, latched: only the
//               slope term g_b (B - 20), since a constant offset leaves a lead unchanged)
//   +contact    absolute + the contact reading of the blank at clamping latched at the cut start
//               (machine/field.h blank_contact_std_k; NaN without it)
// Each test-day cut is scored as the evaluation scores the machine half: the machine's truth
// along the cut minus the compensation held from the latest control sample (strategies.h
// CausalMachineLine), accumulated lead error over the thread [um] (cut_scoring.h TotalOf).
// Beside it the shop's models of the same machine (field_eval.h TrainFieldMachine on the shop
// record of the last estimator_past_days production days and the calendar's tests): warmup,
// schedule, sensors (both_shop's machine half) and grey (both_grey's), scored the same way.
// With grey_structure (opt-in; docs/machine-history.md "Eighth round: diagnosis") the grey
// box's own structure (drift/grey_box.h FitGreyBox with shop_models.h FieldGreyBoxSpec and
// FieldGreyBoxOptions) is also trained on the exact truth, a lead record per past cut with one
// reading per row_step_min (the value m(t, z), sigma 1 um, no probe or laser record), on the
// control logs the ceiling trains on (CeilingGreyColumns): so the gap of the shop's grey box to
// the ceiling splits into its structure (grey on truth against absolute / +blank) and its
// training data (grey on the shop's records against grey on truth). Beside it the error of each
// grey box's blank estimate B latched at the cut start against the blank's true temperature.
#include <string>
#include <vector>

#include "machine_eval/field_eval.h"

namespace whirl::machine_eval {

/// The ceiling's columns, in table order; then the estimators'.
std::vector<std::string> CeilingFeatureSets();  ///< none .. +blank, +contact (above)
std::vector<std::string> CeilingEstimators();   ///< uncompensated, warmup, schedule, sensors, grey

struct CeilingOptions {
  FieldEvalOptions field;       ///< machines, seed, calendar (past_days = the ceiling's days)
  int estimator_past_days = 5;  ///< the shop's models: the last this many past days (1..past_days)
  double row_step_min = 1;      ///< training rows along a past cut, min (0.1..30)
  bool grey_structure = false;  ///< also CeilingGreyColumns and the blank errors (header comment)
};

/// The grey-structure columns (grey_structure), each the grey box trained on the exact truth:
///   grey truth         the field grey box (its sensors, lags, blank as ambient's lag, priors,
///                      forward-chaining choices) on every past day's cuts;
///   grey truth blank   the same with B the blank's TRUE temperature at the cut start (a log
///                      column of it, read through a lag of 1e-3 min: latched exactly);
///   grey truth all     every sensor of the log on both channels, the extra ones with a prior 0;
///   grey truth last    the field grey box on the last estimator_past_days days only.
std::vector<std::string> CeilingGreyColumns();
/// The grey boxes whose latched blank estimate is compared with the truth: shop (both_grey's,
/// the shop's records), truth (grey truth), truth blank (grey truth blank: 0 by construction).
std::vector<std::string> CeilingBlankModels();

/// Per cut of one scenario and seed: the accumulated lead error of the machine half [um] per
/// feature set (CeilingFeatureSets order) and per estimator (CeilingEstimators order).
struct CeilingCut {
  int machine = 0, day = 0, job = 0;
  std::vector<double> ceiling_um, estimator_um;
  std::vector<double> grey_um;        ///< CeilingGreyColumns order (empty without grey_structure)
  std::vector<double> blank_error_k;  ///< CeilingBlankModels order: B latched - true [K]
};

struct CeilingScenario {
  std::string scenario;
  std::vector<std::uint64_t> seeds;
  std::vector<CeilingCut> cuts;
  /// Medians over every cut of every seed.
  std::vector<double> ceiling_median_um, estimator_median_um;
  std::vector<double> grey_median_um;  ///< CeilingGreyColumns (grey_structure)
  /// Per CeilingBlankModels: the median and the 95th percentile of |B latched - true| [K].
  std::vector<double> blank_error_median_k, blank_error_p95_k;
};

/// One scenario over seeds field.seed .. + seeds - 1 (1..20). Needs the workpiece model for the
/// history screws' leads the shop's models learn from (field_eval.h FieldHistoryResidual).
CeilingScenario EvaluateCeiling(const machine::MachineScenario& scenario,
                                const workpiece::WorkpieceModel& model,
                                const compare::ExperienceRule& rule,
                                const lead::IsoToleranceTable& iso_table,
                                const CeilingOptions& options, int seeds,
                                const compare::EvaluateProgress& progress = {});

/// The Markdown table: per scenario the ceiling's medians and the estimators' [um].
std::string FormatCeilingTable(const std::vector<CeilingScenario>& rows);

/// The grey-structure table (rows evaluated with grey_structure): per scenario absolute, +blank,
/// the grey columns, the shop's grey, the two gaps (structure: grey truth - absolute; training
/// data: the shop's grey - grey truth) [um], and the blank errors [K] (median / 95 %).
std::string FormatGreyStructureTable(const std::vector<CeilingScenario>& rows);

}  // namespace whirl::machine_eval
