#pragma once
// The machine evaluation over seeds (machine_eval.h; each seed draws new machines, calendars and
// screws, field_eval.h EvaluateFieldOverSeeds): pooled median and worst accumulated lead error per
// strategy, within 1000 mm and over the thread, with the range (min-max) of the per-seed medians,
// the median |e_a - c| (ISO 3408-3 mean travel deviation against the specified travel compensation
// c) and the P3/P5 shares beside. Headlines name the strongest sensor-free strategy (the smallest
// pooled thread median among every row whose machine half uses no temperature sensor, `none`
// excluded; chosen on the test screws themselves, which can only flatter it) and the gain of the
// sensor strategies over it. An evaluation whose screws hold the opt-in rows (machine_eval.h
// OffsetCandidate) gives them after the table's rows, in the tables, the headlines and the JSON.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "machine_eval/machine_eval.h"

namespace whirl::machine_eval {

struct SeedsEvaluation {
  std::string scenario;
  std::vector<std::uint64_t> seeds;
  std::vector<MachineEvaluation> runs;  ///< one per seed (the report screw only in the first)
  double travel_c_um = 0;               ///< specified travel compensation c, um
};

struct SeedStats {
  double acc1000_median_um = 0, acc1000_worst_um = 0, total_median_um = 0, total_worst_um = 0;
  double acc1000_seed_min_um = 0, acc1000_seed_max_um = 0;  ///< range of per-seed medians
  double total_seed_min_um = 0, total_seed_max_um = 0;
  double e_a_minus_c_median_um = 0, share_p3 = 0, share_p5 = 0;
  std::size_t screws = 0;
};

std::array<SeedStats, kMachineStrategyCount> SummarizeOverSeeds(const SeedsEvaluation& e);

/// The strongest sensor-free strategy by pooled thread median (see the header comment).
MachineStrategy StrongestSensorFree(const std::array<SeedStats, kMachineStrategyCount>& s);

/// The shop-trainable strategy whose machine model the report's combined 840D programs apply
/// (ReportScrew::programs_strategy): both_grey whenever the grey box was fitted (`grey_fitted`),
/// else both_shop. A rule fixed before any test day (the grey box left less than both_shop in
/// every scenario of the documented 1-week evaluation), never a choice on the test screws: `reason`
/// says which and gives both pooled thread medians on the test screws for information only.
MachineStrategy ProgramsStrategy(const std::array<SeedStats, kMachineStrategyCount>& s,
                                 bool grey_fitted, std::string* reason);

/// Sentences: the strongest sensor-free rule and the gain 1 - median(x) / median(best) over the
/// thread of both_shop and both_shop_monitor, with the per-seed range of the gain; then the
/// verdicts, each naming the "both" row it judges: whether both_shop beats the strongest
/// sensor-free rule over the thread (pooled gain > 0) and in how many seeds, and both_shop
/// against the better of the sensor-free machine rules (warmup, schedule: the value of the
/// sensors alone); then the same two for both_shop_monitor (the sensor model kept valid by the
/// set-up checks).
std::vector<std::string> MachineHeadlines(const SeedsEvaluation& e);

/// Notes under the headlines: the thread median of the strongest sensor-free strategy and of
/// both_shop per start type (cold, warm, interrupted, long_pause) with the screw count, and the
/// uncompensated error over the thread of each source alone (median um).
std::vector<std::string> ScenarioNotes(const SeedsEvaluation& e);

/// One block: scenario, strategy, 1000 mm median [seed range], worst, thread median [range],
/// worst, |e_a - c| median, P3 / P5; then the headlines.
std::string FormatSeedsTable(const SeedsEvaluation& e, bool markdown);

/// Several scenarios in one table (one header, the rows of each, then each one's headlines).
std::string FormatScenarioTables(const std::vector<SeedsEvaluation>& e, bool markdown);

/// Schema "whirl.machine_evaluate" version 3: per strategy the pooled statistics and per-seed
/// medians, the headlines, and each seed's evaluation (machine_eval.h to_json).
void to_json(nlohmann::json& j, const SeedsEvaluation& e);

}  // namespace whirl::machine_eval
