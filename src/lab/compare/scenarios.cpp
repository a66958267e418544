#include "compare/scenarios.h"

#include <cstdio>

#include "core/csv.h"
#include "core/error.h"
#include "core/random.h"

namespace whirl::compare {

std::vector<Scenario> NamedScenarios() {
  const sim::DisturbanceOptions today;  // the library defaults (header of sim/simulator.h)
  std::vector<Scenario> s;
  s.push_back({"today",
               "heat partition std 3 %, alpha std 2 %, drift std 0.2 K/h, noise 0.25 um",
               today,
               {},
               false});
  Scenario heat{"heat-spread", "heat partition std 12.5 % (10-15 %), rest as today", today, {}};
  heat.disturbance.heat_partition_rel_std = 0.125;
  s.push_back(heat);
  Scenario drift{"ambient-drift", "ambient drift std 0.5 K/h (|r| < 1 K/h in 95 %)", today, {}};
  drift.disturbance.ambient_drift_std_k_per_h = 0.5;
  s.push_back(drift);
  Scenario wear{"tool-wear", "heat input +20 % linearly over the cut, rest as today", today, {}};
  wear.disturbance.tool_wear_heat_rise_rel = 0.20;
  s.push_back(wear);
  Scenario rest{
      "steady-rest", "60 W rest friction 300 mm ahead of the cut, rest as today", today, {}};
  rest.disturbance.steady_rest_heat_w = 60.0;
  s.push_back(rest);
  Scenario out{"out-of-range",
               "today's levels; D 40-125 mm, lead 5-20 mm, 120-250 m/min, one outside training",
               today,
               {}};
  out.ranges.min = {60, 40, 5, 3, 120};
  out.ranges.max = {65, 125, 20, 10, 250};
  out.out_of_range = true;
  s.push_back(out);
  return s;
}

std::vector<Scenario> SelectScenarios(const std::string& names) {
  const std::vector<Scenario> all = NamedScenarios();
  if (names == "all") return all;
  std::vector<Scenario> chosen;
  std::size_t start = 0;
  while (start <= names.size()) {
    const std::size_t end = std::min(names.find(',', start), names.size());
    const std::string name = names.substr(start, end - start);
    bool found = false;
    for (const auto& s : all)
      if (s.name == name) chosen.push_back(s), found = true;
    if (!found) {
      std::string known;
      for (const auto& s : all) known += (known.empty() ? "" : ", ") + s.name;
      throw InputError("--scenarios: unknown scenario '" + name + "' (known: all, " + known + ")");
    }
    start = end + 1;
  }
  return chosen;
}

namespace {

bool OutsideTraining(const ProcessInputs& p, const InputRanges& t) {
  auto out = [](double x, double lo, double hi) { return x < lo || x > hi; };
  return out(p.diameter_mm, t.min.diameter_mm, t.max.diameter_mm) ||
         out(p.pitch_mm, t.min.pitch_mm, t.max.pitch_mm) ||
         out(p.cutting_speed_m_min, t.min.cutting_speed_m_min, t.max.cutting_speed_m_min);
}

}  // namespace

std::vector<screw::Screw> ScenarioScrews(const Scenario& scenario, const screw::Screw& base, int count,
                                       std::uint64_t seed, const InputRanges& training) {
  if (!scenario.out_of_range) return RandomFeasibleScrews(base, count, seed, scenario.ranges);
  std::vector<screw::Screw> screws;
  const auto draws = RandomFeasibleScrews(base, 20 * count, seed, scenario.ranges);
  for (const auto& s : draws) {
    if (static_cast<int>(screws.size()) == count) break;
    if (!OutsideTraining(s.process, training)) continue;
    screws.push_back(s);
    screws.back().name = "outside-" + std::to_string(screws.size());
  }
  if (static_cast<int>(screws.size()) < count)
    throw InputError("scenario " + scenario.name + ": fewer than " + std::to_string(count) +
                     " screws outside the training ranges among " + std::to_string(draws.size()) +
                     " draws");
  return screws;
}

std::vector<ScenarioResult> RunScenarios(const std::vector<Scenario>& scenarios,
                                         const screw::Screw& base, const workpiece::WorkpieceModel& model,
                                         const ExperienceRule& rule,
                                         const lead::IsoToleranceTable& iso_table,
                                         const ScenarioOptions& options,
                                         const EvaluateProgress& progress) {
  if (options.seeds < 1 || options.random < 1)
    throw InputError("scenarios: --random and --seeds must be >= 1");
  std::vector<ScenarioResult> results;
  for (const Scenario& sc : scenarios) {
    if (sc.out_of_range && !options.allow_extrapolation)
      throw InputError("scenario " + sc.name +
                       ": the network extrapolates outside its training ranges; pass "
                       "--allow-extrapolation to evaluate it explicitly");
    std::vector<EvaluatedScrew> pooled;
    for (int k = 0; k < options.seeds; ++k) {
      const std::uint64_t seed = options.evaluate.seed + static_cast<std::uint64_t>(k);
      EvaluateOptions eo = options.evaluate;
      eo.seed = seed;
      eo.compare.disturbance = sc.disturbance;
      const auto screws = ScenarioScrews(sc, base, options.random, seed + 1000003);
      const Evaluation e = EvaluateScrews(screws, model, rule, iso_table, eo, progress);
      pooled.insert(pooled.end(), e.screws.begin(), e.screws.end());
    }
    results.push_back({sc, Summarize(pooled)});
  }
  return results;
}

std::string FormatScenarioTable(const std::vector<ScenarioResult>& results, bool markdown) {
  std::string out;
  char buf[256];
  if (markdown) {
    out +=
        "| scenario | strategy | 1000 mm median um | 1000 mm worst um | thread median um | "
        "thread worst um |\n|---|---|---|---|---|---|\n";
  } else {
    std::snprintf(buf, sizeof buf, "%-14s %-12s %18s %18s %18s %18s\n", "scenario", "strategy",
                  "1000 mm median um", "1000 mm worst um", "thread median um", "thread worst um");
    out += buf;
  }
  for (const auto& r : results) {
    for (std::size_t k = 0; k < kStrategyCount; ++k) {
      const AbsoluteStats& a = r.summary.absolute[k];
      const char* fmt = markdown ? "| %s | %s | %.2f | %.1f | %.2f | %.1f |\n"
                                 : "%-14s %-12s %18.2f %18.1f %18.2f %18.1f\n";
      std::snprintf(buf, sizeof buf, fmt, r.scenario.name.c_str(), ToString(kStrategies[k]).c_str(),
                    a.acc1000_median_um, a.acc1000_worst_um, a.total_median_um, a.total_worst_um);
      out += buf;
    }
  }
  return out;
}

void to_json(nlohmann::json& j, const ScenarioResult& r) {
  j = nlohmann::json{{"scenario", r.scenario.name},
                     {"levels", r.scenario.description},
                     {"out_of_range", r.scenario.out_of_range},
                     {"summary", r.summary}};
}

}  // namespace whirl::compare
