#include "machine_eval/cut_scoring.h"

#include <utility>

#include "core/error.h"
#include "lead/lead.h"

namespace whirl::machine_eval::detail {

void CheckCount(int v, int lo, int hi, const char* what) {
  if (v < lo || v > hi)
    throw InputError(std::string(what) + " = " + std::to_string(v) + ": must be within " +
                     std::to_string(lo) + ".." + std::to_string(hi));
}

double TotalOf(const ElongationCurve& truth, const compare::CompensationFunction& comp, double feed,
               const screw::Screw& screw, const compare::CompareOptions& options) {
  lead::LeadMetricOptions mo = options.metrics;
  mo.lead_mm = screw.process.pitch_mm;
  const lead::LeadDeviation lead = compare::CutLeadDeviation(
      truth, comp, feed, screw.thread_length_mm, screw.process.pitch_mm, options.cut);
  return lead::ComputeLeadMetrics(lead, mo).accumulated_total_um;
}

interp::CompensationPlan FeaturePlan(const compare::ScrewComparison& c, const Features& tf,
                                     double thread_length_mm,
                                     const compare::CompareOptions& options) {
  if (!(tf.max_elongation_um > 0 && tf.settle_time_s > 0)) return {};
  return interp::BuildPlan(
      fit::ArctanCurve::FromFeatures(tf, options.shape_k, options.time_exponent),
      c.kinematics.axial_feed_mm_s, thread_length_mm, options.plan);
}

compare::CompensationFunction Planned(const interp::CompensationPlan& plan, double feed_mm_s) {
  if (plan.segments.empty()) return compare::NoCompensation();
  return [plan, feed_mm_s](double t_s) {
    return interp::AppliedCompensationUm(plan,
                                         interp::AxisPositionMm(plan.options, feed_mm_s, t_s));
  };
}

compare::CompensationFunction Sum(compare::CompensationFunction a,
                                  compare::CompensationFunction b) {
  return [a, b](double t) { return a(t) + b(t); };
}

void ScoreOne(const ElongationCurve& truth, const compare::CompensationFunction& compensation,
              double feed_mm_s, const screw::Screw& screw, const compare::CompareOptions& options,
              const lead::IsoToleranceTable& iso_table, lead::LeadMetrics* metrics,
              lead::IsoClass* iso, lead::LeadDeviation* lead) {
  lead::LeadMetricOptions mo = options.metrics;
  mo.lead_mm = screw.process.pitch_mm;
  lead::LeadDeviation l = compare::CutLeadDeviation(
      truth, compensation, feed_mm_s, screw.thread_length_mm, screw.process.pitch_mm, options.cut);
  *metrics = lead::ComputeLeadMetrics(l, mo);
  *iso = lead::EvaluateIsoClass(*metrics, iso_table).reached;
  if (lead) *lead = std::move(l);
}

void ScoreStrategies(
    const ElongationCurve& truth,
    const std::array<compare::CompensationFunction, kMachineStrategyCount>& compensations,
    double feed_mm_s, const screw::Screw& screw, const compare::CompareOptions& options,
    const lead::IsoToleranceTable& iso_table, MachineEvalScrew* out,
    std::array<lead::LeadDeviation, kMachineStrategyCount>* leads) {
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    ScoreOne(truth, compensations[k], feed_mm_s, screw, options, iso_table, &out->metrics[k],
             &out->iso[k], leads ? &(*leads)[k] : nullptr);
}

}  // namespace whirl::machine_eval::detail
