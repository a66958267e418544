#pragma once
// The lead error a real-size screw gets with each compensation strategy, cut in the simulator
// (Li, Ma and Jiang's comparison; ISO 3408-3):
//
//   none         c(t) = 0
//   ramp         c(t) = P_class min(1, t / T), the previous experience rule (compare/traditional.h)
//   traditional  the strongest history rule (compare/history_rules.h: class, table or nearest,
//                chosen by leave-one-out on the history, never on the screw being cut) ->
//                arctangent curve -> 840D plan (as model)
//   regression   log-linear least squares on the history -> arctangent curve -> 840D plan
//   model        workpiece::Predict -> fit::ArctanCurve::FromFeatures -> interp::BuildPlan with the
//                screw's kinematics -> c(t) = interp::AppliedCompensationUm(plan, P(t)), i.e. the
//                value the 840D reconstructs from SD43900/SD43910/SD43920 at the axis position
//                P(t) = interp::AxisPositionMm(plan options, feed, t).
//   class        the diameter-class means (P_class, T_class) -> arctangent curve -> 840D plan
//   table        the experience table (raceway radius x speed x lead) -> curve -> 840D plan
//   nearest      the 3 nearest past screws' mean features -> curve -> 840D plan
//
// Truth: sim::Simulate over the whole thread with the seeded disturbances ON (per-workpiece heat
// partition and expansion coefficient, ambient drift) that the model never saw. The groove is
// displaced by the true (noise-free) elongation: the sensor noise of the simulated recording is a
// property of the recording, not of the screw. Lead deviation per strategy: compare/cut.h.
// Metrics: lead/metrics.h with lead_mm = the screw's lead; ISO class: lead/iso3408.h.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compare/cut.h"
#include "lead/iso3408.h"
#include "lead/metrics.h"
#include "compare/traditional.h"
#include "fit/arctan_curve.h"
#include "interp/sinumerik.h"
#include "workpiece/model.h"
#include "screw/screw.h"
#include "sim/simulator.h"

namespace whirl::compare {

enum class Strategy {
  kNone,
  kRamp,
  kTraditional,
  kRegression,
  kModel,
  kClass,
  kTable,
  kNearest
};
inline constexpr std::size_t kStrategyCount = 8;
inline constexpr std::array<Strategy, kStrategyCount> kStrategies = {
    Strategy::kNone,  Strategy::kRamp,  Strategy::kTraditional, Strategy::kRegression,
    Strategy::kModel, Strategy::kClass, Strategy::kTable,       Strategy::kNearest};
/// "none", "ramp", "traditional", "regression", "model", "class", "table", "nearest"
std::string ToString(Strategy s);

struct CompareOptions {
  /// Seed of the truth's disturbances (sim::DisturbanceOptions::seed).
  std::uint64_t seed = 1;
  /// Disturbances of the truth; `enabled` and `seed` are set from `disturbances_on` and `seed`.
  sim::DisturbanceOptions disturbance;
  bool disturbances_on = true;
  /// Simulator numerics; duration_s is forced to 0 (the whole thread).
  sim::SimOptions sim;
  /// 840D plan options (tolerance, axis, sign, MD32760 cap, ...).
  interp::PlanOptions plan;
  /// Shape k and time exponent p of the predicted arctangent curve (fit/arctan_curve.h).
  double shape_k = fit::kDefaultShapeK;
  double time_exponent = fit::kDefaultTimeExponent;
  /// Metric options; lead_mm is set to the screw's lead.
  lead::LeadMetricOptions metrics;
  CutOptions cut;
  /// Also cut the model's +-1 sd band (ScrewComparison::band_leads: two more plans and cuts, for
  /// the report's lead plots; evaluations over many screws leave it off).
  bool band = false;
};

struct StrategyOutcome {
  Strategy strategy = Strategy::kNone;
  lead::LeadDeviation lead;  ///< travel deviation along the thread, um (sign: lead/lead.h)
  lead::LeadMetrics metrics;
  lead::IsoVerdict iso;
};

/// Reduction of each metric by one strategy against a baseline, percent:
/// 100 (1 - |metric| / |baseline metric|); nullopt when the baseline metric is below 1e-9 um
/// (the ratio would be meaningless and could overflow to infinity).
struct MetricReductions {
  std::optional<double> e_a_pct, v_u_pct, v_300_pct, v_2pi_pct, accumulated_1000_pct,
      accumulated_total_pct;
};
MetricReductions Reductions(const lead::LeadMetrics& strategy, const lead::LeadMetrics& baseline);
/// A reduction in words, |pct| with `decimals` decimals: "12.3 % less than" (pct >= 0) or
/// "5.0 % more than" (pct < 0: the strategy's error is larger than the baseline's).
std::string ReductionWords(double pct, int decimals);

struct ScrewComparison {
  screw::Screw screw;
  screw::Kinematics kinematics;
  std::uint64_t seed = 0;
  bool disturbances_on = true;
  sim::AppliedDisturbances disturbances;
  ElongationCurve truth;  ///< noise-free truth elongation of the unmachined section, um
  /// Features of the recorded (noisy) truth over the training table's window
  /// (sim::DatasetOptions::window_s, 1800 s) or the whole cut if shorter: what the model learns.
  Features truth_features;
  workpiece::Prediction prediction;  ///< model prediction for the screw's five inputs
  std::string model_description;     ///< workpiece::WorkpieceModel::Describe() of the model
  std::string model_family;  ///< workpiece::WorkpieceModel::FamilyLabel(): "power law", ...
  fit::ArctanCurve predicted_curve;
  interp::CompensationPlan plan;
  ExperienceClass experience_class;  ///< the traditional rule's class of this screw
  double experience_ramp_time_s = 0;
  /// Features the curve-based baselines use: the strongest history rule (traditional),
  /// regression (zero when the history has no regression baseline: the strategy then equals
  /// none), and each history rule (HistoryRule order: class, table, nearest).
  Features traditional_features, regression_features;
  std::array<Features, kHistoryRuleCount> history_features{};
  HistoryRule traditional_rule = HistoryRule::kClass;  ///< which rule "traditional" is
  /// Compensation applied at the truth's sample times, um, per strategy (kStrategies order).
  std::array<std::vector<double>, kStrategyCount> compensation_um;
  std::array<StrategyOutcome, kStrategyCount> outcomes;  ///< in kStrategies order
  /// The +-1 sd of each strategy's compensation at its plateau, um (kStrategies order), from
  /// training data only, never from this screw: a history rule (ramp, class, table, nearest;
  /// traditional: its rule's; regression) its leave-one-out mean relative error on the past
  /// screws (compare/history_rules.h's score, ExperienceRule) times its plateau; model: the
  /// prediction's sd of the plateau; none: 0. `band_relative`: the same as a fraction of the
  /// plateau. 0 where the error cannot be computed (e.g. a regression on fewer than 8 screws).
  std::array<double, kStrategyCount> band_sd_um{};
  std::array<double, kStrategyCount> band_relative{};
  /// The +-1 sd band of the prediction: the arctangent curves of (L - sd_L, t_s + sd_t) and
  /// (L + sd_L, t_s - sd_t), the two corners that move the whole curve down and up (t_s at least
  /// 1 s, L at least 0), and the model's travel deviation had its plan been made from each (the
  /// same 840D planning and cut; empty where a band curve has no plan, e.g. L - sd_L <= 0, or
  /// without CompareOptions::band).
  std::array<fit::ArctanCurve, 2> band_curves;
  std::array<lead::LeadDeviation, 2> band_leads;
  MetricReductions model_vs_traditional, model_vs_none, traditional_vs_none, model_vs_regression,
      model_vs_ramp;

  const StrategyOutcome& Outcome(Strategy s) const;
  /// "reference: accumulated 1000 mm none 85.1 / traditional 31.0 / model 3.2 um (-89.7 % vs
  /// traditional), classes none/T7/P3".
  std::string BriefReport() const;
};

/// Runs the comparison for one screw. InputError for an infeasible screw, invalid options, or a
/// plan the control cannot run (slope beyond MD32760).
ScrewComparison CompareScrew(const screw::Screw& screw, const workpiece::WorkpieceModel& model,
                             const ExperienceRule& rule, const lead::IsoToleranceTable& iso_table,
                             const CompareOptions& options = {});

/// A screw like `base` (length, thread length, machine settings) with other process inputs.
screw::Screw ScrewWithInputs(const screw::Screw& base, const ProcessInputs& inputs,
                           const std::string& name);

/// The demo's "new type" screw, outside the training rows (the paper's new workpiece type I):
/// the reference blank and machine settings (`reference`: length, thread, tools, feed per tooth)
/// with new process inputs inside the training ranges but unlike any training row:
/// hardness 61 HRC, diameter 63 mm, lead 12 mm, raceway radius 4.0 mm, cutting speed 200 m/min.
/// Name "new-type_63x12x6000".
screw::Screw NewTypeScrew(const screw::Screw& reference);

void to_json(nlohmann::json& j, const MetricReductions& r);
/// Summary JSON (schema "whirl.compare", version 1): screw, kinematics, disturbances, features
/// (truth, predicted, stddev), plan summary, experience class, per strategy metrics + ISO verdict,
/// reductions. Curves are not included (the report writes them as CSV).
void to_json(nlohmann::json& j, const ScrewComparison& c);
inline constexpr int kCompareSchemaVersion = 1;

}  // namespace whirl::compare
