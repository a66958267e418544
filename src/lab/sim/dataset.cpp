#include "sim/dataset.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "core/parallel.h"
#include "core/random.h"

namespace whirl::sim {
namespace {

double RadicalInverse(std::uint64_t index, std::uint64_t base) {
  double inv_base = 1.0 / static_cast<double>(base), f = inv_base, r = 0.0;
  while (index > 0) {
    r += f * static_cast<double>(index % base);
    index /= base;
    f *= inv_base;
  }
  return r;
}

}  // namespace

screw::Screw RowScrew(const ProcessInputs& inputs) {
  screw::Screw s = screw::ReferenceScrew();
  s.name = "table_row";
  s.process = inputs;
  return s;
}

std::vector<ProcessInputs> DesignPoints(
    int count, std::uint64_t seed, const std::array<InputRange, ProcessInputs::kCount>& ranges) {
  if (count < 1)
    throw InputError("dataset: count = " + std::to_string(count) +
                     " breaks the rule: must be >= 1");
  for (int d = 0; d < ProcessInputs::kCount; ++d)
    if (!(ranges[d].max >= ranges[d].min) || !std::isfinite(ranges[d].min) ||
        !std::isfinite(ranges[d].max))
      throw InputError(std::string("dataset: range of ") + kInputColumns[d] + " = [" +
                       FormatNumber(ranges[d].min) + ", " + FormatNumber(ranges[d].max) +
                       "] breaks the rule: min <= max, finite");
  static constexpr std::uint64_t kBases[ProcessInputs::kCount] = {2, 3, 5, 7, 11};
  Rng rng(MixSeed(seed, 0xD351A7ull));
  std::array<double, ProcessInputs::kCount> shift{};
  for (double& s : shift) s = rng.Uniform();
  std::vector<ProcessInputs> points;
  const std::uint64_t max_candidates = 1000ull * static_cast<std::uint64_t>(count);
  for (std::uint64_t i = 1; i <= max_candidates && static_cast<int>(points.size()) < count; ++i) {
    std::array<double, ProcessInputs::kCount> x{};
    for (int d = 0; d < ProcessInputs::kCount; ++d) {
      double u = RadicalInverse(i, kBases[d]) + shift[d];
      u -= std::floor(u);
      x[d] = ranges[d].min + u * (ranges[d].max - ranges[d].min);
    }
    const ProcessInputs p = ProcessInputs::FromArray(x);
    try {
      screw::ValidateScrew(RowScrew(p));
    } catch (const InputError&) {
      continue;  // infeasible combination: skipped by design
    }
    points.push_back(p);
  }
  if (static_cast<int>(points.size()) < count)
    throw InputError("dataset: only " + std::to_string(points.size()) + " feasible points of " +
                     std::to_string(count) + " requested within the ranges");
  return points;
}

Dataset GenerateDataset(const DatasetOptions& options,
                        const std::function<void(std::size_t, std::size_t)>& progress) {
  if (!(options.window_s > 0))
    throw InputError("dataset: window_s = " + FormatNumber(options.window_s) +
                     " breaks the rule: must be positive");
  const std::vector<ProcessInputs> points =
      DesignPoints(options.count, options.seed, options.ranges);
  const std::size_t n = points.size();
  Dataset out;
  out.curves.resize(n);
  out.settle.resize(n);
  out.table.inputs = points;
  out.table.targets.resize(n);

  SimOptions sim = options.sim;
  sim.duration_s = options.window_s;
  ParallelFor(
      n, std::max(1, options.threads),
      [&](std::size_t i) {
        DisturbanceOptions dist = options.disturbance;
        dist.seed = MixSeed(options.seed, i);
        SimulationResult r = Simulate(RowScrew(points[i]), sim, dist);
        out.settle[i] = fit::AnalyzeSettle(r.curve, sim.settle);
        out.table.targets[i] = out.settle[i].features;
        out.curves[i] = std::move(r.curve);
      },
      progress);

  const DisturbanceOptions& d = options.disturbance;
  std::ostringstream s;
  auto& c = out.table.comments;
  c.push_back(" SIMULATED data (not measured): whirl hard-whirling thermal simulator (src/lab/sim).");
  s << " design: " << n << " feasible Halton points, seed " << options.seed
    << ", ranges hardness 60-65 HRC etc. as in datasets/README.md";
  if (options.ranges[0].min != 60 || options.ranges[4].max != 210) s << " (custom ranges)";
  c.push_back(s.str());
  s.str("");
  s << " blank: 6000 mm, thread 5100 mm, 6 tools, 0.01 mm per tool; window " << options.window_s
    << " s; dx " << sim.cell_size_mm << " mm; dt " << sim.time_step_s << " s";
  c.push_back(s.str());
  s.str("");
  if (d.enabled)
    s << " disturbances ON, row seed MixSeed(" << options.seed << ", row): heat partition std "
      << (d.workpiece_variation ? d.heat_partition_rel_std : 0) << ", expansion std "
      << (d.workpiece_variation ? d.expansion_rel_std : 0) << ", ambient drift std "
      << (d.ambient_drift ? d.ambient_drift_std_k_per_h : 0) << " K/h, noise std "
      << (d.measurement_noise ? d.measurement_noise_std_um : 0) << " um";
  else
    s << " disturbances OFF";
  c.push_back(s.str());
  c.push_back(
      " features: fit::ExtractFeatures (plateau + quadratic drift fitted after the settle time, "
      "detrended 60 s moving average within a noise-aware 2 % band; src/product/fit/features.h)");
  return out;
}

void WriteDataset(const Dataset& dataset, const std::filesystem::path& table_path,
                  const std::filesystem::path& curves_dir, const std::string& regenerate) {
  const std::string table = FormatProcessTable(dataset.table);
  if (curves_dir.empty()) {
    WriteFileAtomic(table_path, table);
    return;
  }
  OutputDir curves(curves_dir, "--curves-dir");
  const std::string table_name = table_path.filename().string();
  for (std::size_t i = 0; i < dataset.curves.size(); ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "row_%04zu.csv", i + 1);
    const ElongationCurve& c = dataset.curves[i];
    std::vector<std::vector<double>> rows;
    rows.reserve(c.size());
    for (std::size_t k = 0; k < c.size(); ++k) rows.push_back({c.time_s[k], c.elongation_um[k]});
    curves.Add(name,
               FormatCsv({"time_s", "elongation_um"}, rows,
                         {" SIMULATED curve of row " + std::to_string(i + 1) + " of " + table_name,
                          regenerate}));
  }
  curves.Commit({{table_path, table}});  // the table and its curves: all or nothing
}

}  // namespace whirl::sim
