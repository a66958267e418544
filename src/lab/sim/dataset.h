#pragma once
// Process tables for training and validation, simulated (the ranges of Li, Ma and Jiang's paper
// and its 20 training + 5 validation samples). The paper's own tables are not public.
//
// Design: a space-filling Halton sequence (bases 2, 3, 5, 7, 11) with a seeded Cranley-Patterson
// shift (every coordinate shifted by a uniform offset, modulo 1), mapped linearly to the ranges;
// points whose screw is infeasible (ValidateScrew: ball too large for the lead, groove too deep)
// are skipped, so the table fills the FEASIBLE part of the box evenly.
// Each row: the reference blank (ReferenceScrew(): 6000 mm, thread 5100 mm, 6 tools, 0.01 mm per
// tool, 20 degC) with the row's five inputs, simulated for `window_s` with disturbances seeded by
// MixSeed(seed, row index); features extracted from the recorded (noisy) curve by ExtractFeatures.
#include <cstdint>
#include <functional>
#include <vector>

#include "core/curve.h"
#include "core/process.h"
#include "sim/simulator.h"

namespace whirl::sim {

struct InputRange {
  double min = 0, max = 0;
};

struct DatasetOptions {
  int count = 20;          ///< rows, >= 1
  std::uint64_t seed = 1;  ///< design shift and per-row disturbance seeds
  /// The paper's training ranges, in the column order of kInputColumns.
  std::array<InputRange, ProcessInputs::kCount> ranges = {
      {{60, 65}, {50, 100}, {6, 16}, {3, 10}, {150, 210}}};
  /// Simulated time per row, s: long enough that the slowest row (100 mm, 150 m/min, settle ~650 s)
  /// has its plateau in the settle analysis's tail window.
  double window_s = 1800.0;
  SimOptions sim;  ///< numerics; duration_s is set to window_s
  DisturbanceOptions disturbance = EnabledDisturbances();  ///< seed replaced per row
  int threads = 2;  ///< worker threads (the rows are independent)

  /// Disturbances of the table rows: all on, ambient drift std 0.05 K/h (a short, 30 min run on a
  /// machine in a conditioned hall; with 0.2 K/h the drift of the 5 m unmachined section, ~2 um in
  /// 30 min, is 10-20 % of the plateau and makes settle times scatter by up to 120 %).
  static DisturbanceOptions EnabledDisturbances() {
    DisturbanceOptions d;
    d.enabled = true;
    d.ambient_drift_std_k_per_h = 0.05;
    return d;
  }
};

struct Dataset {
  ProcessTable table;                   ///< inputs and features, with provenance comments
  std::vector<ElongationCurve> curves;  ///< recorded curve of each row
  std::vector<fit::SettleAnalysis> settle;   ///< settle analysis of each row
};

/// The first `count` feasible design points (InputError if the ranges are empty/inverted or fewer
/// than `count` feasible points exist among 1000 * count candidates).
std::vector<ProcessInputs> DesignPoints(
    int count, std::uint64_t seed, const std::array<InputRange, ProcessInputs::kCount>& ranges);

/// Simulates every design point (in `threads` threads; the result does not depend on the thread
/// count). `progress(done, total)` is called under a lock after each row.
Dataset GenerateDataset(const DatasetOptions& options,
                        const std::function<void(std::size_t, std::size_t)>& progress = {});

/// Writes the table (CSV, `table_path`) and, unless `curves_dir` is empty, each row's recorded
/// curve as `curves_dir/row_0001.csv`, ... (time_s,elongation_um; the directory follows
/// core/output_dir.h's rule: new, empty or a whirl output, never a symbolic link), all-or-nothing:
/// one file that cannot be written leaves none written and previous files intact. `regenerate` (the
/// command line) goes into every curve's '#' comments.
void WriteDataset(const Dataset& dataset, const std::filesystem::path& table_path,
                  const std::filesystem::path& curves_dir, const std::string& regenerate);

/// The reference blank with the given inputs (the screw of a table row).
screw::Screw RowScrew(const ProcessInputs& inputs);

}  // namespace whirl::sim
