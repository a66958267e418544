#pragma once
// Named scenarios of `whirl evaluate --scenarios`: truth the model has not
// seen. Each scenario is a set of disturbance levels of the simulated truth (sim/simulator.h
// DisturbanceOptions) and a range of screws; every strategy (compare/compare.h) is judged against
// it. The levels (assumptions, stated so they can be argued with):
//   today              the default truth: heat partition std 3 %, expansion coefficient std 2 %,
//                      ambient drift std 0.2 K/h, sensor noise 0.25 um; training ranges.
//   heat-spread        heat partition std 12.5 % (the 10-15 %: blank batches, edge
//                      preparation, coolant), other levels as today.
//   ambient-drift      ambient drift std 0.5 K/h, i.e. up to 1 K/h in 95 % of the screws (an
//                      unconditioned hall), other levels as today.
//   tool-wear          heat input rising linearly by 20 % over the cut (flank wear over one 2 h
//                      tool life), other levels as today.
//   steady-rest        60 W of friction heat from a steady rest riding 300 mm ahead of the cut on
//                      the unmachined side (20 mm pad), other levels as today.
//   out-of-range       today's levels, screws with diameter, lead or cutting speed outside the
//                      training ranges (diameter 40-125 mm, lead 5-20 mm, 120-250 m/min, at least
//                      one of the three outside 50-100 mm, 6-16 mm, 150-210 m/min). The network
//                      extrapolates: only run with the explicit override (allow_extrapolation).
// Summary per scenario and strategy: median and worst |accumulated lead error| within 1000 mm and
// over the thread, um (compare/evaluate.h AbsoluteStats).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "compare/evaluate.h"

namespace whirl::compare {

struct Scenario {
  std::string name;
  std::string description;  ///< the levels, one line
  sim::DisturbanceOptions disturbance;
  InputRanges ranges;         ///< random screws are drawn here
  bool out_of_range = false;  ///< keep only screws outside the training ranges (extrapolates)
};

/// The scenarios above, in that order.
std::vector<Scenario> NamedScenarios();

/// Scenarios by comma-separated names ("all" = every one); InputError names an unknown name and
/// lists the known ones.
std::vector<Scenario> SelectScenarios(const std::string& names);

/// `count` random screws of the scenario (for out_of_range: the first `count` feasible draws with
/// a diameter, lead or speed outside the training ranges `training`).
std::vector<screw::Screw> ScenarioScrews(const Scenario& scenario, const screw::Screw& base, int count,
                                       std::uint64_t seed, const InputRanges& training = {});

struct ScenarioResult {
  Scenario scenario;
  EvaluationSummary summary;  ///< pooled over the seeds
};

struct ScenarioOptions {
  EvaluateOptions evaluate;  ///< plan, curve shape, threads; disturbance levels are replaced
  int random = 40;           ///< screws per scenario and seed
  int seeds = 1;             ///< seeds seed .. seed + seeds - 1
  /// The explicit override of the extrapolation guard: without it an out-of-range scenario is an
  /// InputError.
  bool allow_extrapolation = false;
};

/// Runs every scenario (same screws for the in-range scenarios at a seed, so their rows differ
/// only by the disturbance levels).
std::vector<ScenarioResult> RunScenarios(const std::vector<Scenario>& scenarios,
                                         const screw::Screw& base, const workpiece::WorkpieceModel& model,
                                         const ExperienceRule& rule,
                                         const lead::IsoToleranceTable& iso_table,
                                         const ScenarioOptions& options,
                                         const EvaluateProgress& progress = {});

/// The sensitivity table (scenario x strategy: median / worst um within 1000 mm and over the
/// thread) as fixed-width text and as Markdown (docs/results.md quotes it).
std::string FormatScenarioTable(const std::vector<ScenarioResult>& results, bool markdown);

void to_json(nlohmann::json& j, const ScenarioResult& r);

}  // namespace whirl::compare
