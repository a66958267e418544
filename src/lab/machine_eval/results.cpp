// The results' types of machine_eval.h: the strategies' names, the summary of one evaluation and
// its JSON.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "compare/evaluate.h"
#include "machine_eval/machine_eval.h"

namespace whirl::machine_eval {

std::array<MachineStrategy, kMachineStrategyCount> MachineStrategies() {
  std::array<MachineStrategy, kMachineStrategyCount> all{};
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) all[k] = static_cast<MachineStrategy>(k);
  return all;
}

std::string ToString(MachineStrategy s) {
  static const char* kNames[] = {"none",       "traditional",  "workpiece", "class",
                                 "table",      "nearest",      "warmup",    "schedule",
                                 "lead_slope", "machine_shop", "both_shop", "both_shop_monitor",
                                 "both_grey"};
  static_assert(sizeof kNames / sizeof kNames[0] == kMachineStrategyCount);
  return kNames[static_cast<int>(s)];
}

bool UsesSensors(MachineStrategy s) {
  return s == MachineStrategy::kMachineShop || s == MachineStrategy::kBothShop ||
         s == MachineStrategy::kBothShopMonitor || s == MachineStrategy::kBothGrey;
}

std::string ToString(OffsetCandidate c) {
  return c == OffsetCandidate::kGreyWarmupOffset ? "grey_warmup_k0" : "grey_mean_k0";
}

double WarmupOffsetShare(OffsetCandidate c) {
  return c == OffsetCandidate::kGreyWarmupOffset ? 1.0 : 0.5;
}

std::string ToString(GreyCandidate c) {
  static const char* kNames[] = {"grey_all_sensors",
                                 "grey_sensors_by_days",
                                 "grey_short_prior",
                                 "grey_short_offset_as_read",
                                 "grey_short_offset_one_lag",
                                 "grey_guarded",
                                 "grey_short_mix",
                                 "grey_short_mix_fixed"};
  static_assert(sizeof kNames / sizeof kNames[0] == kGreyCandidateCount);
  return kNames[static_cast<int>(c)];
}

std::string OptInRowName(std::size_t k) {
  return k < kOffsetCandidateCount
             ? ToString(static_cast<OffsetCandidate>(k))
             : ToString(static_cast<GreyCandidate>(k - kOffsetCandidateCount));
}

std::string ToString(ErrorSource s) {
  static const char* kNames[] = {"workpiece", "head", "z_axis"};
  return kNames[static_cast<int>(s)];
}

MachineEvalSummary SummarizeMachineEval(const std::vector<MachineEvalScrew>& screws) {
  MachineEvalSummary s;
  s.screws = screws.size();
  std::array<std::vector<double>, kMachineStrategyCount> acc;
  std::array<std::vector<double>, kErrorSourceCount> sources;
  std::size_t ok = 0;
  for (const auto& r : screws) {
    if (!r.ok) {
      ++s.failed;
      continue;
    }
    ++ok;
    for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
      acc[k].push_back(std::abs(r.metrics[k].accumulated_1000_um));
    for (std::size_t q = 0; q < kErrorSourceCount; ++q) sources[q].push_back(r.source_total_um[q]);
    if (r.residual_workpiece_total_um >= r.residual_machine_total_um)
      ++s.residual_workpiece_dominates;
    else
      ++s.residual_machine_dominates;
  }
  auto median = [](std::vector<double> v) {
    return v.empty() ? 0.0 : compare::Stats(std::move(v)).median_pct;
  };
  for (std::size_t q = 0; q < kErrorSourceCount; ++q) s.source_median_um[q] = median(sources[q]);
  auto at = [&](MachineStrategy x) { return median(acc[static_cast<std::size_t>(x)]); };
  using S = MachineStrategy;
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "%zu screws (%zu failed): within 1000 mm median none %.1f, traditional %.1f, workpiece "
      "%.1f, warmup %.1f, schedule %.1f, both_shop %.1f, both_shop_monitor %.1f um; what is "
      "left after both_shop is dominated by the %s part in %zu of %zu screws",
      s.screws, s.failed, at(S::kNone), at(S::kTraditional), at(S::kWorkpiece), at(S::kWarmup),
      at(S::kSchedule), at(S::kBothShop), at(S::kBothShopMonitor),
      s.residual_machine_dominates > s.residual_workpiece_dominates ? "machine" : "workpiece",
      std::max(s.residual_machine_dominates, s.residual_workpiece_dominates), ok);
  s.message = buf;
  return s;
}

void to_json(nlohmann::json& j, const MachineEvaluation& e) {
  const MachineEvalSummary& s = e.summary;
  nlohmann::json sources = nlohmann::json::object();
  for (std::size_t q = 0; q < kErrorSourceCount; ++q)
    sources[ToString(static_cast<ErrorSource>(q))] = s.source_median_um[q];
  nlohmann::json screws = nlohmann::json::array();
  for (const auto& r : e.screws) {
    nlohmann::json x = {{"name", r.screw.name},
                        {"machine", r.machine},
                        {"seed", r.seed},
                        {"day_seed", r.day_seed},
                        {"ok", r.ok}};
    if (!r.ok) {
      x["error"] = r.error;
    } else {
      for (MachineStrategy st : MachineStrategies()) {
        const auto k = static_cast<std::size_t>(st);
        x["strategies"][ToString(st)] = {{"metrics", r.metrics[k]},
                                         {"iso_class", ToString(r.iso[k])}};
      }
      for (std::size_t c = 0; c < r.candidate_metrics.size(); ++c)
        x["strategies"][OptInRowName(c)] = {{"metrics", r.candidate_metrics[c]},
                                            {"iso_class", ToString(r.candidate_iso[c])}};
      x["day"] = r.day;
      x["start_type"] = r.start_type;
      x["residual_workpiece_total_um"] = r.residual_workpiece_total_um;
      x["residual_machine_total_um"] = r.residual_machine_total_um;
    }
    screws.push_back(x);
  }
  nlohmann::json grey_fit = nlohmann::json::array();
  for (const auto& g : e.grey_fit)
    grey_fit.push_back({{"prior_strength", g.prior_strength},
                        {"time_constants_min", g.time_constants_min},
                        {"blank_tau_min", g.blank_tau_min},
                        {"cv_rmse_um", g.cv_rmse_um},
                        {"lead_days", g.lead_days}});
  j = {{"schema", "whirl.machine_evaluate_run"},
       {"schema_version", 1},
       {"summary",
        {{"screws", s.screws},
         {"failed", s.failed},
         {"uncompensated_total_by_source_median_um", sources},
         {"residual_after_both_shop_dominated_by_workpiece", s.residual_workpiece_dominates},
         {"residual_after_both_shop_dominated_by_machine", s.residual_machine_dominates},
         {"message", s.message}}},
       {"sensor_model_sensors", e.sensors},
       {"sensor_model_choice", e.sensors_choice},
       {"grey_guarded_choice", e.guard_choice},
       {"grey_short_mix_weight", e.short_mix_weight},
       {"grey_fit", grey_fit},
       {"screws", screws}};
}

}  // namespace whirl::machine_eval
