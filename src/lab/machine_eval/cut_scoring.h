#pragma once
// Pieces of the evaluation of one cut (field_eval.h): a history rule's curve as an 840D plan,
// what a plan applies, the sum of two compensations, and the scoring of every strategy's lead
// deviation (compare/cut.h) with its ISO 3408-3 class.
#include <array>

#include "compare/compare.h"
#include "compare/cut.h"
#include "machine_eval/machine_eval.h"

namespace whirl::machine_eval::detail {

/// InputError "<what> = <v>: must be within lo..hi" unless lo <= v <= hi.
void CheckCount(int v, int lo, int hi, const char* what);

/// Accumulated lead error over the thread of `truth` under `comp`, um.
double TotalOf(const ElongationCurve& truth, const compare::CompensationFunction& comp, double feed,
               const screw::Screw& screw, const compare::CompareOptions& options);

/// A history rule's curve as an 840D plan (empty when the rule has no features for the screw).
interp::CompensationPlan FeaturePlan(const compare::ScrewComparison& c, const Features& tf,
                                     double thread_length_mm,
                                     const compare::CompareOptions& options);

/// What a plan applies at time t_s (none for an empty plan). The plan is kept by the function.
compare::CompensationFunction Planned(const interp::CompensationPlan& plan, double feed_mm_s);

compare::CompensationFunction Sum(compare::CompensationFunction a, compare::CompensationFunction b);

/// Metrics and ISO class of one compensation on the truth; `lead` (optional) keeps the lead.
void ScoreOne(const ElongationCurve& truth, const compare::CompensationFunction& compensation,
              double feed_mm_s, const screw::Screw& screw, const compare::CompareOptions& options,
              const lead::IsoToleranceTable& iso_table, lead::LeadMetrics* metrics,
              lead::IsoClass* iso, lead::LeadDeviation* lead = nullptr);

/// Metrics and ISO class of every strategy on the truth; `leads` (optional) keeps the leads.
void ScoreStrategies(
    const ElongationCurve& truth,
    const std::array<compare::CompensationFunction, kMachineStrategyCount>& compensations,
    double feed_mm_s, const screw::Screw& screw, const compare::CompareOptions& options,
    const lead::IsoToleranceTable& iso_table, MachineEvalScrew* out,
    std::array<lead::LeadDeviation, kMachineStrategyCount>* leads = nullptr);

}  // namespace whirl::machine_eval::detail
