#include "compare/evaluate.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/csv.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/random.h"

namespace whirl::compare {

std::vector<screw::Screw> RandomFeasibleScrews(const screw::Screw& base, int count, std::uint64_t seed,
                                             const InputRanges& ranges) {
  if (count < 0)
    throw InputError("random screw count = " + std::to_string(count) + ": must be >= 0");
  Rng rng(seed);
  const auto lo = ranges.min.ToArray(), hi = ranges.max.ToArray();
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    if (!(hi[i] >= lo[i]))
      throw InputError(std::string("input range of ") + kInputColumns[i] + ": max " +
                       FormatNumber(hi[i]) + " < min " + FormatNumber(lo[i]));
  std::vector<screw::Screw> screws;
  for (int k = 0; k < count; ++k) {
    for (int attempt = 0;; ++attempt) {
      if (attempt == 1000)
        throw InputError("1000 random draws in a row gave infeasible screws: check the ranges");
      std::array<double, ProcessInputs::kCount> a{};
      for (int i = 0; i < ProcessInputs::kCount; ++i)
        a[i] = lo[i] + (hi[i] - lo[i]) * rng.Uniform();
      screw::Screw s =
          ScrewWithInputs(base, ProcessInputs::FromArray(a), "random-" + std::to_string(k + 1));
      try {
        screw::ValidateScrew(s, s.name);
      } catch (const InputError&) {
        continue;
      }
      screws.push_back(s);
      break;
    }
  }
  return screws;
}

std::vector<screw::Screw> ScrewsFromTable(const screw::Screw& base, const ProcessTable& table,
                                        const std::string& prefix) {
  std::vector<screw::Screw> screws;
  for (std::size_t r = 0; r < table.inputs.size(); ++r) {
    screw::Screw s = ScrewWithInputs(base, table.inputs[r], prefix + "-" + std::to_string(r + 1));
    const std::string line =
        r < table.line_numbers.size() ? ":" + std::to_string(table.line_numbers[r]) : "";
    screw::ValidateScrew(s, table.source + line);
    screws.push_back(s);
  }
  return screws;
}

ReductionStats Stats(std::vector<double> values) {
  ReductionStats s;
  s.count = values.size();
  if (values.empty()) return s;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  s.median_pct = n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
  s.worst_pct = values.front();
  s.best_pct = values.back();
  return s;
}

Evaluation EvaluateScrews(const std::vector<screw::Screw>& screws, const workpiece::WorkpieceModel& model,
                          const ExperienceRule& rule, const lead::IsoToleranceTable& iso_table,
                          const EvaluateOptions& options, const EvaluateProgress& progress) {
  if (options.threads < 1)
    throw InputError("threads = " + std::to_string(options.threads) + ": must be >= 1");
  Evaluation e;
  e.screws.resize(screws.size());
  // A screw with bad input (InputError) is recorded as a failed screw; any other exception (a bug,
  // bad_alloc) stops the run and reaches the caller through ParallelFor.
  ParallelFor(
      screws.size(), options.threads,
      [&](std::size_t i) {
        EvaluatedScrew& out = e.screws[i];
        out.screw = screws[i];
        out.seed = MixSeed(options.seed, i);
        CompareOptions co = options.compare;
        co.seed = out.seed;
        try {
          const ScrewComparison c = CompareScrew(screws[i], model, rule, iso_table, co);
          out.ok = true;
          out.outside_domain = c.prediction.outside_domain;
          for (std::size_t k = 0; k < kStrategyCount; ++k) {
            out.metrics[k] = c.outcomes[k].metrics;
            out.iso[k] = c.outcomes[k].iso.reached;
          }
          out.model_vs_traditional = c.model_vs_traditional;
          out.model_vs_none = c.model_vs_none;
          out.model_vs_regression = c.model_vs_regression;
          out.model_vs_ramp = c.model_vs_ramp;
        } catch (const InputError& err) {
          out.ok = false;
          out.error = err.what();
        }
      },
      progress);

  e.summary = Summarize(e.screws);
  return e;
}

namespace {

double MedianOf(std::vector<double> v) { return v.empty() ? 0.0 : Stats(std::move(v)).median_pct; }
double WorstOf(const std::vector<double>& v) {
  return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
}

}  // namespace

EvaluationSummary Summarize(const std::vector<EvaluatedScrew>& screws) {
  EvaluationSummary s;
  s.screws = screws.size();
  std::vector<double> acc_t, total_t, acc_n, acc_r, acc_ramp;
  std::array<std::vector<double>, kStrategyCount> acc, total;
  std::array<std::size_t, kStrategyCount> p3{}, p5{};
  std::size_t ok = 0;
  auto push = [](std::vector<double>& v, const std::optional<double>& x) {
    if (x) v.push_back(*x);
  };
  for (const auto& r : screws) {
    if (!r.ok) {
      ++s.failed;
      continue;
    }
    ++ok;
    push(acc_t, r.model_vs_traditional.accumulated_1000_pct);
    push(total_t, r.model_vs_traditional.accumulated_total_pct);
    push(acc_n, r.model_vs_none.accumulated_1000_pct);
    push(acc_r, r.model_vs_regression.accumulated_1000_pct);
    push(acc_ramp, r.model_vs_ramp.accumulated_1000_pct);
    for (std::size_t k = 0; k < kStrategyCount; ++k) {
      acc[k].push_back(std::abs(r.metrics[k].accumulated_1000_um));
      total[k].push_back(std::abs(r.metrics[k].accumulated_total_um));
      const lead::IsoClass c = r.iso[k];
      if (c == lead::IsoClass::kP1 || c == lead::IsoClass::kP3) ++p3[k];
      if (c == lead::IsoClass::kP1 || c == lead::IsoClass::kP3 || c == lead::IsoClass::kP5) ++p5[k];
    }
  }
  s.acc1000_vs_traditional = Stats(acc_t);
  s.total_vs_traditional = Stats(total_t);
  s.acc1000_vs_none = Stats(acc_n);
  s.acc1000_vs_regression = Stats(acc_r);
  s.acc1000_vs_ramp = Stats(acc_ramp);
  for (std::size_t k = 0; k < kStrategyCount; ++k) {
    s.absolute[k] = {MedianOf(acc[k]), WorstOf(acc[k]), MedianOf(total[k]), WorstOf(total[k])};
    s.share_p3[k] = ok > 0 ? static_cast<double>(p3[k]) / ok : 0.0;
    s.share_p5[k] = ok > 0 ? static_cast<double>(p5[k]) / ok : 0.0;
  }
  std::string m = std::to_string(s.screws) + " screws (" + std::to_string(s.failed) +
                  " failed): accumulated error within 1000 mm, median (worst) um:";
  char buf[256];
  for (std::size_t k = 0; k < kStrategyCount; ++k) {
    std::snprintf(buf, sizeof buf, " %s %.2f (%.1f)", ToString(kStrategies[k]).c_str(),
                  s.absolute[k].acc1000_median_um, s.absolute[k].acc1000_worst_um);
    m += buf;
  }
  std::snprintf(buf, sizeof buf,
                "; model vs traditional (the strongest history rule, chosen by leave-one-out on "
                "the history): median reduction %.1f %%, vs regression %.1f %%",
                s.acc1000_vs_traditional.median_pct, s.acc1000_vs_regression.median_pct);
  s.message = m + buf;
  return s;
}

namespace {
nlohmann::json StatsJson(const ReductionStats& r) {
  return {{"count", r.count},
          {"median_pct", r.median_pct},
          {"worst_pct", r.worst_pct},
          {"best_pct", r.best_pct}};
}
}  // namespace

void to_json(nlohmann::json& j, const EvaluatedScrew& s) {
  j = nlohmann::json{{"name", s.screw.name}, {"seed", s.seed}, {"ok", s.ok}};
  const auto in = s.screw.process.ToArray();
  for (int i = 0; i < ProcessInputs::kCount; ++i) j[kInputColumns[i]] = in[i];
  if (!s.ok) {
    j["error"] = s.error;
    return;
  }
  j["outside_domain"] = s.outside_domain;
  nlohmann::json strategies = nlohmann::json::object();
  for (std::size_t k = 0; k < kStrategyCount; ++k)
    strategies[ToString(kStrategies[k])] = {{"metrics", s.metrics[k]},
                                            {"iso_class", ToString(s.iso[k])}};
  j["strategies"] = strategies;
  j["model_vs_traditional"] = s.model_vs_traditional;
  j["model_vs_none"] = s.model_vs_none;
  j["model_vs_regression"] = s.model_vs_regression;
  j["model_vs_ramp"] = s.model_vs_ramp;
}

void to_json(nlohmann::json& j, const EvaluationSummary& s) {
  nlohmann::json p3 = nlohmann::json::object(), p5 = nlohmann::json::object(),
                 absolute = nlohmann::json::object();
  for (std::size_t k = 0; k < kStrategyCount; ++k) {
    const std::string name = ToString(kStrategies[k]);
    p3[name] = s.share_p3[k];
    p5[name] = s.share_p5[k];
    absolute[name] = {{"accumulated_1000_median_um", s.absolute[k].acc1000_median_um},
                      {"accumulated_1000_worst_um", s.absolute[k].acc1000_worst_um},
                      {"accumulated_total_median_um", s.absolute[k].total_median_um},
                      {"accumulated_total_worst_um", s.absolute[k].total_worst_um}};
  }
  j = nlohmann::json{{"screws", s.screws},
                     {"failed", s.failed},
                     {"absolute_um", absolute},
                     {"accumulated_1000_model_vs_regression", StatsJson(s.acc1000_vs_regression)},
                     {"accumulated_1000_model_vs_ramp", StatsJson(s.acc1000_vs_ramp)},
                     {"accumulated_1000_model_vs_traditional", StatsJson(s.acc1000_vs_traditional)},
                     {"accumulated_total_model_vs_traditional", StatsJson(s.total_vs_traditional)},
                     {"accumulated_1000_model_vs_none", StatsJson(s.acc1000_vs_none)},
                     {"share_reaching_p3", p3},
                     {"share_reaching_p5", p5},
                     {"message", s.message}};
}

void to_json(nlohmann::json& j, const Evaluation& e) {
  j = nlohmann::json{{"schema", "whirl.evaluate"},
                     {"schema_version", 2},
                     {"summary", e.summary},
                     {"screws", e.screws}};
}

}  // namespace whirl::compare
