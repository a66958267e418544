#pragma once
// Evaluation over many screws: the comparison of compare/compare.h over the
// validation table and N random feasible screws, each with its own seeded disturbances, and the
// figures that summarize it: median and worst reduction of the accumulated lead error against the
// traditional compensation, and the share of screws that reach ISO 3408-3 P3 and P5.
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compare/compare.h"

namespace whirl::compare {

/// Ranges of the random screws: the paper's training ranges (Li, Ma and Jiang).
struct InputRanges {
  ProcessInputs min{60, 50, 6, 3, 150};
  ProcessInputs max{65, 100, 16, 10, 210};
};

/// `count` random screws like `base` (same length, thread length and machine settings) with inputs
/// drawn uniformly in `ranges` (core/random.h's Rng from `seed`, the same set on every platform);
/// a draw that sim::ValidateScrew rejects (e.g. a raceway too wide for the lead) is drawn again.
/// Names "random-<k>". InputError if 1000 draws in a row are infeasible.
std::vector<screw::Screw> RandomFeasibleScrews(const screw::Screw& base, int count, std::uint64_t seed,
                                             const InputRanges& ranges = {});

/// Screws like `base` with the inputs of each row of a process table. Names "<prefix>-<row>"
/// (1-based row). Rows that sim::ValidateScrew rejects are an InputError naming the file line.
std::vector<screw::Screw> ScrewsFromTable(const screw::Screw& base, const ProcessTable& table,
                                        const std::string& prefix);

struct EvaluateOptions {
  CompareOptions compare;  ///< per screw; its seed is replaced by MixSeed(seed, screw index)
  std::uint64_t seed = 1;  ///< base seed of the disturbances
  int threads = 2;         ///< worker threads (>= 1)
};

/// The figures kept per screw (the full comparison is not kept: it holds whole curves).
struct EvaluatedScrew {
  screw::Screw screw;
  std::uint64_t seed = 0;
  bool ok = false;
  std::string error;            ///< the InputError message when !ok (e.g. a slope beyond MD32760)
  bool outside_domain = false;  ///< the model extrapolated
  std::array<lead::LeadMetrics, kStrategyCount> metrics;  ///< kStrategies order
  std::array<lead::IsoClass, kStrategyCount> iso = [] {
    std::array<lead::IsoClass, kStrategyCount> a{};
    a.fill(lead::IsoClass::kNone);
    return a;
  }();
  MetricReductions model_vs_traditional, model_vs_none, model_vs_regression, model_vs_ramp;
};

struct ReductionStats {
  std::size_t count = 0;                               ///< screws with a defined reduction
  double median_pct = 0, worst_pct = 0, best_pct = 0;  ///< worst = smallest reduction
};

/// Absolute accumulated lead error of one strategy over the screws, um (median and worst =
/// largest), within 1000 mm and over the thread.
struct AbsoluteStats {
  double acc1000_median_um = 0, acc1000_worst_um = 0, total_median_um = 0, total_worst_um = 0;
};

struct EvaluationSummary {
  std::size_t screws = 0, failed = 0;
  std::array<AbsoluteStats, kStrategyCount> absolute;  ///< kStrategies order: the lead figures
  ReductionStats acc1000_vs_traditional, total_vs_traditional, acc1000_vs_none,
      acc1000_vs_regression, acc1000_vs_ramp;
  /// Share (0..1) of the evaluated screws reaching P3 (P1 or P3) and P5 (P1, P3 or P5), by
  /// strategy.
  std::array<double, kStrategyCount> share_p3{}, share_p5{};
  std::string message;  ///< one line with the headline numbers
};

struct Evaluation {
  std::vector<EvaluatedScrew> screws;
  EvaluationSummary summary;
};

/// Progress callback: screws done, total.
using EvaluateProgress = std::function<void(std::size_t done, std::size_t total)>;

/// Compares every screw (in parallel on `threads` threads; results in input order and identical
/// for any thread count). A screw whose comparison throws InputError is recorded as failed; any
/// other exception (in a comparison or in `progress`) stops the run and is rethrown here after all
/// threads have joined (core/parallel.h), never std::terminate.
Evaluation EvaluateScrews(const std::vector<screw::Screw>& screws, const workpiece::WorkpieceModel& model,
                          const ExperienceRule& rule, const lead::IsoToleranceTable& iso_table,
                          const EvaluateOptions& options, const EvaluateProgress& progress = {});

/// The summary of evaluated screws (those of one run, or pooled over several seeds).
EvaluationSummary Summarize(const std::vector<EvaluatedScrew>& screws);

/// Median (mean of the two middle values for an even count), worst (min) and best (max).
ReductionStats Stats(std::vector<double> values);

void to_json(nlohmann::json& j, const EvaluatedScrew& s);
void to_json(nlohmann::json& j, const EvaluationSummary& s);
void to_json(nlohmann::json& j, const Evaluation& e);

}  // namespace whirl::compare
