#include "machine_eval/summary.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "compare/evaluate.h"
#include "core/numbers.h"
#include "machine_eval/shop_models.h"

namespace whirl::machine_eval {

namespace {

double Median(std::vector<double> v) {
  return v.empty() ? 0.0 : compare::Stats(std::move(v)).median_pct;
}
double Max(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
}
double Min(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::min_element(v.begin(), v.end());
}

bool ReachesP(lead::IsoClass c, int p) {
  using lead::IsoClass;
  return c == IsoClass::kP1 || c == IsoClass::kP3 || (p == 5 && c == IsoClass::kP5);
}

// Row k of a screw: the table's strategies, then the opt-in rows (OptInRowName order).
const lead::LeadMetrics& MetricsOf(const MachineEvalScrew& r, std::size_t k) {
  return k < kMachineStrategyCount ? r.metrics[k] : r.candidate_metrics[k - kMachineStrategyCount];
}
lead::IsoClass IsoOf(const MachineEvalScrew& r, std::size_t k) {
  return k < kMachineStrategyCount ? r.iso[k] : r.candidate_iso[k - kMachineStrategyCount];
}

// The row's name (k as in MetricsOf).
std::string RowName(std::size_t k) {
  return k < kMachineStrategyCount ? ToString(static_cast<MachineStrategy>(k))
                                   : OptInRowName(k - kMachineStrategyCount);
}

// The opt-in rows the evaluation holds (those of its first screw evaluated without error).
std::size_t CandidateRows(const SeedsEvaluation& e) {
  for (const MachineEvaluation& run : e.runs)
    for (const MachineEvalScrew& r : run.screws)
      if (r.ok) return r.candidate_metrics.size();
  return 0;
}

SeedStats StatsOf(const SeedsEvaluation& e, std::size_t k) {
  SeedStats s;
  std::vector<double> acc, tot, ea, seed_acc, seed_tot;
  std::size_t p3 = 0, p5 = 0;
  for (const MachineEvaluation& run : e.runs) {
    std::vector<double> a, t;
    for (const MachineEvalScrew& r : run.screws) {
      if (!r.ok) continue;
      const lead::LeadMetrics& m = MetricsOf(r, k);
      a.push_back(std::abs(m.accumulated_1000_um));
      t.push_back(std::abs(m.accumulated_total_um));
      ea.push_back(std::abs(m.e_a_um - e.travel_c_um));
      p3 += ReachesP(IsoOf(r, k), 3);
      p5 += ReachesP(IsoOf(r, k), 5);
    }
    seed_acc.push_back(Median(a));
    seed_tot.push_back(Median(t));
    acc.insert(acc.end(), a.begin(), a.end());
    tot.insert(tot.end(), t.begin(), t.end());
  }
  s.screws = acc.size();
  s.acc1000_median_um = Median(acc);
  s.acc1000_worst_um = Max(acc);
  s.total_median_um = Median(tot);
  s.total_worst_um = Max(tot);
  s.acc1000_seed_min_um = Min(seed_acc);
  s.acc1000_seed_max_um = Max(seed_acc);
  s.total_seed_min_um = Min(seed_tot);
  s.total_seed_max_um = Max(seed_tot);
  s.e_a_minus_c_median_um = Median(ea);
  s.share_p3 = s.screws ? static_cast<double>(p3) / s.screws : 0.0;
  s.share_p5 = s.screws ? static_cast<double>(p5) / s.screws : 0.0;
  return s;
}

// Median over the screws of one seed's run of the thread error of row k.
double SeedMedian(const MachineEvaluation& run, std::size_t k) {
  std::vector<double> t;
  for (const auto& r : run.screws)
    if (r.ok) t.push_back(std::abs(MetricsOf(r, k).accumulated_total_um));
  return Median(t);
}

}  // namespace

std::array<SeedStats, kMachineStrategyCount> SummarizeOverSeeds(const SeedsEvaluation& e) {
  std::array<SeedStats, kMachineStrategyCount> s;
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) s[k] = StatsOf(e, k);
  return s;
}

MachineStrategy StrongestSensorFree(const std::array<SeedStats, kMachineStrategyCount>& s) {
  std::size_t best = 0;
  for (MachineStrategy x : MachineStrategies()) {
    const auto k = static_cast<std::size_t>(x);
    if (k == 0 || UsesSensors(x)) continue;
    if (best == 0 || s[k].total_median_um < s[best].total_median_um) best = k;
  }
  return static_cast<MachineStrategy>(best);
}

MachineStrategy ProgramsStrategy(const std::array<SeedStats, kMachineStrategyCount>& s,
                                 bool grey_fitted, std::string* reason) {
  const SeedStats& shop = s[static_cast<std::size_t>(MachineStrategy::kBothShop)];
  const SeedStats& grey = s[static_cast<std::size_t>(MachineStrategy::kBothGrey)];
  const std::string medians = " (thread medians over " + std::to_string(shop.screws) +
                              " test screws, simulated: both_grey " +
                              FormatDecimals(grey.total_median_um, 1) + " um, both_shop " +
                              FormatDecimals(shop.total_median_um, 1) +
                              " um; for information: the rule does not look at them)";
  if (!grey_fitted) {
    *reason = "both_shop: the grey box was not fitted (its sensors are not in the logs)";
    return MachineStrategy::kBothShop;
  }
  *reason = "both_grey: the grey box is the default wherever it can be fitted" + medians;
  return MachineStrategy::kBothGrey;
}

namespace {

// Gain 1 - median(x) / median(ref) over the thread, percent: pooled and per seed.
struct Gain {
  double pooled = 0;
  std::vector<double> per_seed;
  int seeds_won() const {
    return static_cast<int>(
        std::count_if(per_seed.begin(), per_seed.end(), [](double g) { return g > 0; }));
  }
};

// Row k (as in MetricsOf) against the table's row ref.
Gain GainOver(const SeedsEvaluation& e, const std::array<SeedStats, kMachineStrategyCount>& s,
              std::size_t k, std::size_t ref) {
  Gain g;
  for (const auto& run : e.runs) {
    const double r = SeedMedian(run, ref);
    if (r > 1e-9) g.per_seed.push_back(100.0 * (1.0 - SeedMedian(run, k) / r));
  }
  const double x = k < kMachineStrategyCount ? s[k].total_median_um : StatsOf(e, k).total_median_um;
  if (s[ref].total_median_um > 1e-9) g.pooled = 100.0 * (1.0 - x / s[ref].total_median_um);
  return g;
}

// The verdict of a "both" row (both_shop, both_shop_monitor or both_grey) against a reference row.
std::string Verdict(const SeedsEvaluation& e, std::size_t x, const Gain& g, MachineStrategy ref,
                    const char* what) {
  char buf[400];
  if (g.pooled > 0)
    std::snprintf(buf, sizeof buf,
                  "%s: %s (sensors) beats %s %s over the thread by %.1f %% (better in %d of %zu "
                  "seeds)",
                  e.scenario.c_str(), RowName(x).c_str(), what, ToString(ref).c_str(), g.pooled,
                  g.seeds_won(), g.per_seed.size());
  else
    std::snprintf(buf, sizeof buf,
                  "%s: %s (sensors) does NOT beat %s %s over the thread (%+.1f %%; better in %d "
                  "of %zu seeds)",
                  e.scenario.c_str(), RowName(x).c_str(), what, ToString(ref).c_str(), g.pooled,
                  g.seeds_won(), g.per_seed.size());
  return buf;
}

}  // namespace

std::vector<std::string> MachineHeadlines(const SeedsEvaluation& e) {
  const auto s = SummarizeOverSeeds(e);
  const MachineStrategy best = StrongestSensorFree(s);
  const auto b = static_cast<std::size_t>(best);
  std::vector<std::string> out;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "%s: the strongest sensor-free strategy is %s (thread median %.1f um, within "
                "1000 mm %.1f um, over %zu screws and %zu seeds)",
                e.scenario.c_str(), ToString(best).c_str(), s[b].total_median_um,
                s[b].acc1000_median_um, s[b].screws, e.seeds.size());
  out.push_back(buf);
  std::vector<std::size_t> rows;
  for (MachineStrategy x : {MachineStrategy::kBothShop, MachineStrategy::kBothShopMonitor,
                            MachineStrategy::kBothGrey})
    rows.push_back(static_cast<std::size_t>(x));
  for (std::size_t c = 0; c < CandidateRows(e); ++c) rows.push_back(kMachineStrategyCount + c);
  for (std::size_t k : rows) {
    const Gain g = GainOver(e, s, k, b);
    std::snprintf(buf, sizeof buf,
                  "%s vs %s over the thread: %+.1f %% (per seed %+.1f .. %+.1f %%; positive = "
                  "%s leaves less)",
                  RowName(k).c_str(), ToString(best).c_str(), g.pooled, Min(g.per_seed),
                  Max(g.per_seed), RowName(k).c_str());
    out.push_back(buf);
  }
  const MachineStrategy rule =
      s[static_cast<std::size_t>(MachineStrategy::kSchedule)].total_median_um <=
              s[static_cast<std::size_t>(MachineStrategy::kWarmup)].total_median_um
          ? MachineStrategy::kSchedule
          : MachineStrategy::kWarmup;
  for (std::size_t k : rows) {
    out.push_back(Verdict(e, k, GainOver(e, s, k, b), best, "the strongest sensor-free strategy"));
    if (rule != best)
      out.push_back(Verdict(e, k, GainOver(e, s, k, static_cast<std::size_t>(rule)), rule,
                            "the better sensor-free machine rule"));
  }
  return out;
}

std::vector<std::string> ScenarioNotes(const SeedsEvaluation& e) {
  const auto s = SummarizeOverSeeds(e);
  const auto best = static_cast<std::size_t>(StrongestSensorFree(s));
  const auto shop = static_cast<std::size_t>(MachineStrategy::kBothShop);
  std::vector<std::string> out;
  std::string line = e.scenario + ": thread median by start type, " +
                     ToString(static_cast<MachineStrategy>(best)) + " / both_shop um (screws):";
  bool any = false;
  for (const char* type : {"cold", "warm", "interrupted", "long_pause"}) {
    std::vector<double> b, x;
    for (const auto& run : e.runs)
      for (const auto& r : run.screws)
        if (r.ok && r.start_type == type) {
          b.push_back(std::abs(r.metrics[best].accumulated_total_um));
          x.push_back(std::abs(r.metrics[shop].accumulated_total_um));
        }
    if (b.empty()) continue;
    char buf[120];
    std::snprintf(buf, sizeof buf, "%s %s %.1f / %.1f (%zu)", any ? "," : "", type, Median(b),
                  Median(x), b.size());
    line += buf;
    any = true;
  }
  if (any) out.push_back(line);
  line = e.scenario + ": uncompensated over the thread, each source alone, median um:";
  const char* names[] = {"workpiece", "head", "Z axis and blank"};
  for (std::size_t q = 0; q < kErrorSourceCount; ++q) {
    std::vector<double> v;
    for (const auto& run : e.runs)
      for (const auto& r : run.screws)
        if (r.ok) v.push_back(r.source_total_um[q]);
    char buf[80];
    std::snprintf(buf, sizeof buf, "%s %s %.1f", q ? "," : "", names[q], Median(v));
    line += buf;
  }
  out.push_back(line);
  std::size_t machines = 0, grey = 0;
  for (const auto& run : e.runs)
    for (const std::string& c : run.guard_choice) machines++, grey += c == "both_grey";
  if (machines)
    out.push_back(e.scenario + ": grey_guarded applies both_grey's model on " +
                  std::to_string(grey) + " of " + std::to_string(machines) +
                  " machines, the sensor-free rule on the others");
  std::vector<double> w;
  for (const auto& run : e.runs)
    w.insert(w.end(), run.short_mix_weight.begin(), run.short_mix_weight.end());
  if (!w.empty()) {
    char buf[160];
    std::snprintf(
        buf, sizeof buf,
        ": grey_short_mix's weight of the grey box: median %.2f (%.2f .. %.2f), at "
        "the floor on %zu of %zu machines",
        Median(w), *std::min_element(w.begin(), w.end()), *std::max_element(w.begin(), w.end()),
        static_cast<std::size_t>(std::count(w.begin(), w.end(), kShortMixFloor)), w.size());
    out.push_back(e.scenario + buf);
  }
  return out;
}

namespace {

std::string TableHeader(bool markdown) {
  if (markdown)
    return "| scenario | strategy | 1000 mm median [seeds] um | 1000 mm worst um | thread median "
           "[seeds] um | thread worst um | \\|e_a - c\\| median um | P3 / P5 |\n"
           "|---|---|---|---|---|---|---|---|\n";
  // The strategy column holds the longest name (both_shop_monitor, 17 characters).
  return "scenario            strategy          1000mm med [seeds]      worst  thread med "
         "[seeds]      worst  |ea-c|  P3/P5\n";
}

std::string TableRows(const SeedsEvaluation& e, bool markdown) {
  const auto s = SummarizeOverSeeds(e);
  std::string out;
  char buf[400];
  for (std::size_t k = 0; k < kMachineStrategyCount + CandidateRows(e); ++k) {
    const SeedStats x = k < kMachineStrategyCount ? s[k] : StatsOf(e, k);
    const char* fmt = markdown
                          ? "| %s | %s | %.1f [%.1f-%.1f] | %.1f | %.1f [%.1f-%.1f] | %.1f | %.1f "
                            "| %.2f / %.2f |\n"
                          : "%-19s %-17s %6.1f [%5.1f-%5.1f] %6.1f %7.1f [%5.1f-%5.1f] %6.1f "
                            "%6.1f  %.2f/%.2f\n";
    std::snprintf(buf, sizeof buf, fmt, e.scenario.c_str(), RowName(k).c_str(),
                  x.acc1000_median_um, x.acc1000_seed_min_um, x.acc1000_seed_max_um,
                  x.acc1000_worst_um, x.total_median_um, x.total_seed_min_um, x.total_seed_max_um,
                  x.total_worst_um, x.e_a_minus_c_median_um, x.share_p3, x.share_p5);
    out += buf;
  }
  return out;
}

std::string Headlines(const SeedsEvaluation& e, bool markdown) {
  std::string out;
  for (const auto& h : MachineHeadlines(e)) out += (markdown ? "\n- " : "") + h + "\n";
  for (const auto& h : ScenarioNotes(e)) out += (markdown ? "\n- " : "  ") + h + "\n";
  return out;
}

}  // namespace

std::string FormatSeedsTable(const SeedsEvaluation& e, bool markdown) {
  return TableHeader(markdown) + TableRows(e, markdown) + Headlines(e, markdown);
}

std::string FormatScenarioTables(const std::vector<SeedsEvaluation>& e, bool markdown) {
  std::string out = TableHeader(markdown);
  for (const auto& x : e) out += TableRows(x, markdown);
  for (const auto& x : e) out += Headlines(x, markdown);
  out += std::string(markdown ? "\n" : "") +
         "(accumulated lead error in um, median [range of the per-seed medians] and worst screw; "
         "simulator only: every figure is measured in the project's simulator, not on a "
         "machine)\n";
  return out;
}

void to_json(nlohmann::json& j, const SeedsEvaluation& e) {
  const auto s = SummarizeOverSeeds(e);
  nlohmann::json strategies = nlohmann::json::object();
  for (std::size_t k = 0; k < kMachineStrategyCount + CandidateRows(e); ++k) {
    const SeedStats x = k < kMachineStrategyCount ? s[k] : StatsOf(e, k);
    std::vector<double> per_seed;
    for (const auto& run : e.runs) per_seed.push_back(SeedMedian(run, k));
    strategies[RowName(k)] = {
        {"uses_sensors",
         k >= kMachineStrategyCount || UsesSensors(static_cast<MachineStrategy>(k))},
        {"accumulated_1000_median_um", x.acc1000_median_um},
        {"accumulated_1000_worst_um", x.acc1000_worst_um},
        {"accumulated_1000_seed_median_range_um", {x.acc1000_seed_min_um, x.acc1000_seed_max_um}},
        {"accumulated_total_median_um", x.total_median_um},
        {"accumulated_total_worst_um", x.total_worst_um},
        {"accumulated_total_seed_median_range_um", {x.total_seed_min_um, x.total_seed_max_um}},
        {"accumulated_total_median_per_seed_um", per_seed},
        {"e_a_minus_c_median_um", x.e_a_minus_c_median_um},
        {"share_reaching_p3", x.share_p3},
        {"share_reaching_p5", x.share_p5},
        {"screws", x.screws}};
  }
  nlohmann::json runs = nlohmann::json::array();
  for (const auto& r : e.runs) runs.push_back(r);
  j = {{"schema", "whirl.machine_evaluate"},
       {"schema_version", 3},
       {"scenario", e.scenario},
       {"seeds", e.seeds},
       {"travel_c_um", e.travel_c_um},
       {"strongest_sensor_free", ToString(StrongestSensorFree(s))},
       {"strategies", strategies},
       {"headlines", MachineHeadlines(e)},
       {"notes", ScenarioNotes(e)},
       {"runs", runs}};
}

}  // namespace whirl::machine_eval
