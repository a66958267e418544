#include "compare/compare.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/numbers.h"
#include "sim/dataset.h"
#include "fit/features.h"

namespace whirl::compare {

std::string ToString(Strategy s) {
  switch (s) {
    case Strategy::kNone:
      return "none";
    case Strategy::kRamp:
      return "ramp";
    case Strategy::kRegression:
      return "regression";
    case Strategy::kTraditional:
      return "traditional";
    case Strategy::kModel:
      return "model";
    case Strategy::kClass:
      return "class";
    case Strategy::kTable:
      return "table";
    case Strategy::kNearest:
      return "nearest";
  }
  return "none";
}

namespace {

std::optional<double> Reduce(double value, double baseline) {
  // Below 1e-9 um (a femtometre) the ratio means nothing and could overflow: no reduction.
  if (!(std::abs(baseline) >= 1e-9)) return std::nullopt;
  return 100.0 * (1.0 - std::abs(value) / std::abs(baseline));
}

nlohmann::json Optional(const std::optional<double>& v) {
  return v ? nlohmann::json(*v) : nlohmann::json();
}

}  // namespace

MetricReductions Reductions(const lead::LeadMetrics& s, const lead::LeadMetrics& b) {
  MetricReductions r;
  r.e_a_pct = Reduce(s.e_a_um, b.e_a_um);
  r.v_u_pct = Reduce(s.v_u_um, b.v_u_um);
  r.v_300_pct = Reduce(s.v_300_um, b.v_300_um);
  if (s.v_2pi_um && b.v_2pi_um) r.v_2pi_pct = Reduce(*s.v_2pi_um, *b.v_2pi_um);
  r.accumulated_1000_pct = Reduce(s.accumulated_1000_um, b.accumulated_1000_um);
  r.accumulated_total_pct = Reduce(s.accumulated_total_um, b.accumulated_total_um);
  return r;
}

std::string ReductionWords(double pct, int decimals) {
  return FormatDecimals(std::abs(pct), decimals) + (pct < 0 ? " % more than" : " % less than");
}

const StrategyOutcome& ScrewComparison::Outcome(Strategy s) const {
  return outcomes[static_cast<std::size_t>(s)];
}

std::string ScrewComparison::BriefReport() const {
  std::string s = screw.name + ": accumulated within 1000 mm";
  for (const auto& o : outcomes)
    s += " " + ToString(o.strategy) + " " + FormatDecimals(o.metrics.accumulated_1000_um, 1);
  s += " um; whole thread";
  for (const auto& o : outcomes)
    s += " " + ToString(o.strategy) + " " + FormatDecimals(o.metrics.accumulated_total_um, 1);
  s += " um";
  if (model_vs_traditional.accumulated_1000_pct)
    s += " (model " + ReductionWords(*model_vs_traditional.accumulated_1000_pct, 1) +
         " traditional within 1000 mm)";
  s += ", ISO class";
  for (const auto& o : outcomes) s += " " + ToString(o.strategy) + " " + ToString(o.iso.reached);
  return s;
}

screw::Screw ScrewWithInputs(const screw::Screw& base, const ProcessInputs& inputs,
                           const std::string& name) {
  screw::Screw s = base;
  s.process = inputs;
  s.name = name;
  return s;
}

screw::Screw NewTypeScrew(const screw::Screw& reference) {
  ProcessInputs in;
  in.hardness_hrc = 61.0;
  in.diameter_mm = 63.0;
  in.pitch_mm = 12.0;
  in.raceway_radius_mm = 4.0;
  in.cutting_speed_m_min = 200.0;
  return ScrewWithInputs(reference, in, "new-type_63x12x6000");
}

namespace {

// The truth of the comparison: the whole thread simulated with the comparison's disturbances (its
// noise-free curve), and the features as the training table measures them.
void SimulateTruth(const screw::Screw& screw, const CompareOptions& options, ScrewComparison* c) {
  sim::SimOptions sim_options = options.sim;
  sim_options.duration_s = 0.0;
  sim::DisturbanceOptions disturbance = options.disturbance;
  disturbance.enabled = options.disturbances_on;
  disturbance.seed = options.seed;
  const sim::SimulationResult sim = sim::Simulate(screw, sim_options, disturbance);
  c->disturbances = sim.disturbances;
  c->truth.time_s = sim.curve.time_s;
  c->truth.elongation_um = sim.elongation_noise_free_um.size() == sim.curve.size()
                               ? sim.elongation_noise_free_um
                               : sim.curve.elongation_um;
  // Features as the training table measures them: the recorded curve over the dataset's window
  // (sim::DatasetOptions::window_s), not over the whole thread, whose tail is no plateau.
  const double window_s = sim::DatasetOptions{}.window_s;
  ElongationCurve recorded;
  for (std::size_t i = 0; i < sim.curve.size() && sim.curve.time_s[i] <= window_s; ++i) {
    recorded.time_s.push_back(sim.curve.time_s[i]);
    recorded.elongation_um.push_back(sim.curve.elongation_um[i]);
  }
  c->truth_features = recorded.size() >= 10 && sim.curve.time_s.back() >= window_s
                          ? fit::ExtractFeatures(recorded, sim_options.settle)
                          : sim.features;
}

// The 840D plan of a baseline's features with the model's curve shape (none without a positive
// plateau and settle time); `what` names the baseline in errors.
interp::CompensationPlan BaselinePlan(const Features& f, const std::string& what,
                                      const screw::Screw& screw, double feed_mm_s,
                                      const CompareOptions& options) {
  if (!(f.max_elongation_um > 0) || !(f.settle_time_s > 0)) return interp::CompensationPlan{};
  const fit::ArctanCurve curve =
      fit::ArctanCurve::FromFeatures(f, options.shape_k, options.time_exponent);
  curve.Validate(what + " curve of screw '" + screw.name + "'");
  return interp::BuildPlan(curve, feed_mm_s, screw.thread_length_mm, options.plan);
}

// The compensation a plan applies over time (it refers to `plan`, which must outlive it).
CompensationFunction PlannedCompensation(const interp::CompensationPlan& plan, double feed_mm_s) {
  if (plan.segments.empty()) return NoCompensation();
  return [&plan, feed_mm_s](double t_s) {
    return interp::AppliedCompensationUm(plan,
                                         interp::AxisPositionMm(plan.options, feed_mm_s, t_s));
  };
}

// Cuts the truth with each strategy's compensation: compensation over time, lead deviation,
// metrics and ISO class per strategy.
void CutWithEveryStrategy(const std::array<CompensationFunction, kStrategyCount>& comp,
                          const screw::Screw& screw, const lead::IsoToleranceTable& iso_table,
                          const CompareOptions& options, ScrewComparison* c) {
  const double feed = c->kinematics.axial_feed_mm_s;
  lead::LeadMetricOptions metric_options = options.metrics;
  metric_options.lead_mm = screw.process.pitch_mm;
  for (std::size_t k = 0; k < kStrategyCount; ++k) {
    for (double t : c->truth.time_s) c->compensation_um[k].push_back(comp[k](t));
    StrategyOutcome& o = c->outcomes[k];
    o.strategy = kStrategies[k];
    o.lead = CutLeadDeviation(c->truth, comp[k], feed, screw.thread_length_mm,
                              screw.process.pitch_mm, options.cut);
    o.metrics = lead::ComputeLeadMetrics(o.lead, metric_options);
    o.iso = lead::EvaluateIsoClass(o.metrics, iso_table);
  }
  auto vs = [c](Strategy a, Strategy b) {
    return Reductions(c->Outcome(a).metrics, c->Outcome(b).metrics);
  };
  c->model_vs_traditional = vs(Strategy::kModel, Strategy::kTraditional);
  c->model_vs_none = vs(Strategy::kModel, Strategy::kNone);
  c->traditional_vs_none = vs(Strategy::kTraditional, Strategy::kNone);
  c->model_vs_regression = vs(Strategy::kModel, Strategy::kRegression);
  c->model_vs_ramp = vs(Strategy::kModel, Strategy::kRamp);
}

// The band of the prediction (ScrewComparison::band_curves) and the model's travel deviation
// with a plan of each band curve.
void CutWithBand(const screw::Screw& screw, const CompareOptions& options, ScrewComparison* c) {
  const Features& m = c->prediction.mean;
  const Features& sd = c->prediction.stddev;
  const auto curve = [&options](double l_um, double t_s) {
    return fit::ArctanCurve::FromFeatures({std::max(0.0, l_um), std::max(1.0, t_s)},
                                          options.shape_k, options.time_exponent);
  };
  c->band_curves = {
      curve(m.max_elongation_um - sd.max_elongation_um, m.settle_time_s + sd.settle_time_s),
      curve(m.max_elongation_um + sd.max_elongation_um, m.settle_time_s - sd.settle_time_s)};
  const double feed = c->kinematics.axial_feed_mm_s;
  for (std::size_t k = 0; k < 2; ++k) {
    const fit::ArctanCurve& b = c->band_curves[k];
    const Features f{b.max_elongation_um, b.settle_time_s};
    try {
      const interp::CompensationPlan plan =
          BaselinePlan(f, "prediction band", screw, feed, options);
      if (plan.segments.empty()) continue;
      c->band_leads[k] = CutLeadDeviation(c->truth, PlannedCompensation(plan, feed), feed,
                                          screw.thread_length_mm, screw.process.pitch_mm,
                                          options.cut);
    } catch (const InputError&) {
      c->band_leads[k] = {};  // no plan of this band curve: the band is not drawn
    }
  }
}

// ScrewComparison::band_sd_um and band_relative from the history's leave-one-out scores and the
// prediction's sd (after the features are set).
void SetBands(const ExperienceRule& rule, ScrewComparison* c) {
  const auto loo = [&rule](HistoryRule h) {
    return rule.has_choice ? rule.choice.loo_relative_error[static_cast<std::size_t>(h)] : NAN;
  };
  const double model_mean = c->prediction.mean.max_elongation_um;
  const std::array<std::pair<double, double>, kStrategyCount> rel_plateau = {{
      {0.0, 0.0},
      {rule.ramp_loo_relative_error, c->experience_class.plateau_um},
      {loo(c->traditional_rule), c->traditional_features.max_elongation_um},
      {rule.regression_loo_relative_error, c->regression_features.max_elongation_um},
      {model_mean > 0 ? c->prediction.stddev.max_elongation_um / model_mean : 0.0, model_mean},
      {loo(HistoryRule::kClass), c->history_features[0].max_elongation_um},
      {loo(HistoryRule::kTable), c->history_features[1].max_elongation_um},
      {loo(HistoryRule::kNearest), c->history_features[2].max_elongation_um}}};
  for (std::size_t k = 0; k < kStrategyCount; ++k) {
    const auto [rel, plateau] = rel_plateau[k];
    const bool known = std::isfinite(rel) && rel > 0 && plateau > 0;
    c->band_relative[k] = known ? rel : 0.0;
    c->band_sd_um[k] = known ? rel * plateau : 0.0;
  }
}

}  // namespace

ScrewComparison CompareScrew(const screw::Screw& screw, const workpiece::WorkpieceModel& model,
                             const ExperienceRule& rule, const lead::IsoToleranceTable& iso_table,
                             const CompareOptions& options) {
  ScrewComparison c;
  c.screw = screw;
  c.kinematics = screw::ComputeKinematics(screw);  // validates; InputError if infeasible
  c.seed = options.seed;
  c.disturbances_on = options.disturbances_on;
  SimulateTruth(screw, options, &c);

  // Model: prediction -> arctangent curve -> 840D plan.
  c.prediction = workpiece::Predict(model, screw.process);
  c.model_description = model.Describe();
  c.model_family = model.FamilyLabel();
  c.predicted_curve =
      fit::ArctanCurve::FromFeatures(c.prediction.mean, options.shape_k, options.time_exponent);
  c.predicted_curve.Validate("predicted curve of screw '" + screw.name + "'");
  const double feed = c.kinematics.axial_feed_mm_s;
  c.plan = interp::BuildPlan(c.predicted_curve, feed, screw.thread_length_mm, options.plan);

  // Curve baselines: the same shape and the same 840D planning as the model.
  c.experience_class = rule.ClassFor(screw.process.diameter_mm);
  c.experience_ramp_time_s = rule.ramp_time_s;
  c.traditional_rule = rule.has_choice ? rule.choice.chosen : HistoryRule::kClass;
  c.traditional_features = rule.TraditionalFeatures(screw.process);
  std::array<interp::CompensationPlan, kHistoryRuleCount> history_plans;
  for (std::size_t k = 0; k < kHistoryRuleCount; ++k) {
    const HistoryRule h = static_cast<HistoryRule>(k);
    c.history_features[k] = rule.HistoryFeatures(h, screw.process);
    history_plans[k] = BaselinePlan(c.history_features[k], ToString(h), screw, feed, options);
  }
  if (rule.has_regression) c.regression_features = rule.regression.Predict(screw.process);
  const interp::CompensationPlan traditional_plan =
      BaselinePlan(c.traditional_features, "traditional", screw, feed, options);
  const interp::CompensationPlan regression_plan =
      BaselinePlan(c.regression_features, "regression", screw, feed, options);
  const double diameter = screw.process.diameter_mm;
  const std::array<CompensationFunction, kStrategyCount> comp = {
      NoCompensation(),
      [&rule, diameter](double t_s) { return rule.CompensationUm(diameter, t_s); },
      PlannedCompensation(traditional_plan, feed),
      PlannedCompensation(regression_plan, feed),
      PlannedCompensation(c.plan, feed),
      PlannedCompensation(history_plans[0], feed),
      PlannedCompensation(history_plans[1], feed),
      PlannedCompensation(history_plans[2], feed)};
  CutWithEveryStrategy(comp, screw, iso_table, options, &c);
  SetBands(rule, &c);
  if (options.band) CutWithBand(screw, options, &c);
  return c;
}

void to_json(nlohmann::json& j, const MetricReductions& r) {
  j = nlohmann::json{{"e_a_pct", Optional(r.e_a_pct)},
                     {"v_u_pct", Optional(r.v_u_pct)},
                     {"v_300_pct", Optional(r.v_300_pct)},
                     {"v_2pi_pct", Optional(r.v_2pi_pct)},
                     {"accumulated_1000_pct", Optional(r.accumulated_1000_pct)},
                     {"accumulated_total_pct", Optional(r.accumulated_total_pct)}};
}

void to_json(nlohmann::json& j, const ScrewComparison& c) {
  nlohmann::json strategies = nlohmann::json::object();
  for (const auto& o : c.outcomes)
    strategies[ToString(o.strategy)] = {
        {"metrics", o.metrics},
        {"iso", o.iso},
        {"band_sd_um", c.band_sd_um[static_cast<std::size_t>(o.strategy)]}};
  nlohmann::json plan_summary = {{"segments", c.plan.segments.size()},
                                 {"points", c.plan.point_count},
                                 {"uniform_points_for_same_bound", c.plan.uniform_point_count},
                                 {"max_deviation_um", c.plan.max_deviation_um},
                                 {"max_abs_sd43910", c.plan.max_abs_slope},
                                 {"md32760", c.plan.options.md32760},
                                 {"axis", c.plan.options.axis},
                                 {"sign", interp::ToString(c.plan.options.sign)},
                                 {"tolerance_um", c.plan.options.tolerance_um}};
  j = nlohmann::json{{"schema", "whirl.compare"},
                     {"schema_version", kCompareSchemaVersion},
                     {"screw", c.screw},
                     {"kinematics",
                      {{"axial_feed_mm_s", c.kinematics.axial_feed_mm_s},
                       {"axial_feed_mm_min", c.kinematics.axial_feed_mm_min},
                       {"cutting_time_s", c.kinematics.cutting_time_s},
                       {"ring_speed_rpm", c.kinematics.ring_speed_rpm},
                       {"workpiece_speed_rpm", c.kinematics.workpiece_speed_rpm}}},
                     {"truth",
                      {{"seed", c.seed},
                       {"disturbances_on", c.disturbances_on},
                       {"heat_partition_factor", c.disturbances.heat_partition_factor},
                       {"expansion_factor", c.disturbances.expansion_factor},
                       {"ambient_drift_k_per_h", c.disturbances.ambient_drift_k_per_h},
                       {"max_elongation_um", c.truth_features.max_elongation_um},
                       {"settle_time_s", c.truth_features.settle_time_s}}},
                     {"prediction",
                      {{"model", c.model_description},
                       {"max_elongation_um", c.prediction.mean.max_elongation_um},
                       {"settle_time_s", c.prediction.mean.settle_time_s},
                       {"max_elongation_std_um", c.prediction.stddev.max_elongation_um},
                       {"settle_time_std_s", c.prediction.stddev.settle_time_s},
                       {"outside_domain", c.prediction.outside_domain},
                       {"outside_domain_fields", c.prediction.outside_domain_fields},
                       {"shape_k", c.predicted_curve.shape_k},
                       {"time_exponent", c.predicted_curve.time_exponent}}},
                     {"plan", plan_summary},
                     {"ramp",
                      {{"rule", "c(t) = P_class * min(1, t / T)"},
                       {"class_nominal_diameter_mm", c.experience_class.nominal_diameter_mm},
                       {"plateau_um", c.experience_class.plateau_um},
                       {"class_screws", c.experience_class.screws},
                       {"ramp_time_s", c.experience_ramp_time_s}}},
                     {"traditional",
                      {{"rule", "the strongest history rule (leave-one-out on the history), "
                                "arctangent curve, 840D plan"},
                       {"chosen", ToString(c.traditional_rule)},
                       {"max_elongation_um", c.traditional_features.max_elongation_um},
                       {"settle_time_s", c.traditional_features.settle_time_s}}},
                     {"regression",
                      {{"rule", "log-linear least squares on the 5 inputs, arctangent, 840D plan"},
                       {"max_elongation_um", c.regression_features.max_elongation_um},
                       {"settle_time_s", c.regression_features.settle_time_s}}},
                     {"strategies", strategies},
                     {"reductions",
                      {{"model_vs_traditional", c.model_vs_traditional},
                       {"model_vs_none", c.model_vs_none},
                       {"traditional_vs_none", c.traditional_vs_none},
                       {"model_vs_regression", c.model_vs_regression},
                       {"model_vs_ramp", c.model_vs_ramp}}},
                     {"sign_convention",
                      "travel deviation = actual minus specified travel from the thread start, um; "
                      "d(x) = [e(t) - c(t)] - [e(0) - c(0)], x = axial_feed * t"}};
}

}  // namespace whirl::compare
