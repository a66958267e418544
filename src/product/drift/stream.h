#pragma once
// The drift commands on run files too long to hold (a year of a machine's log): each file is read
// block by block (drift/run_file.h RunReader) and every row goes once into what the command needs.
// Memory:
//   predict, monitor --run, split   fixed (a block of 4096 rows, the model's state, running sums;
//                                   outputs are written as the rows arrive);
//   fit                             bounded: the evenly thinned sample of FitFiles (at most
//                                   kSearchSampleCells cells) plus the final fit's running QR;
//   report                          fit's, then predict's per pass over a run shown (the
//                                   model's, one per baseline) plus the plot's decimated rows
//                                   (core/decimate.h: a few thousand); the baselines' fits are
//                                   fit's (drift/report.h).
// Time axis: a streamed command first scans the file (ScanRun: the row count and whether every
// row recorded its time), since the lags need the axis before the first row.
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/run_file.h"

namespace whirl::drift {

/// Progress of a long pass: the step ("reading log.csv"), the rows read so far and the fraction of
/// the file (NaN when not known).
using StreamProgress =
    std::function<void(const std::string& step, long long rows, double fraction)>;

/// What a prediction is reduced to when its samples are not kept: PredictRun's figures.
struct PredictionSummary {
  std::string run;
  long long samples = 0;
  bool time_from_index = false;
  double predicted_min_um = 0, predicted_max_um = 0;
  bool has_measured = false;
  ErrorStats residual;  ///< measured - predicted (when measured)
  ErrorStats none;      ///< the measured error on the model's zero (no compensation)
  long long outside_range_samples = 0, beyond_trained_time_samples = 0;
  std::vector<std::string> warnings;
};
/// The summary of an in-memory prediction (the same figures, from its vectors).
PredictionSummary Summarize(const RunPrediction& p);

/// One predicted sample of a streamed run, in order.
struct PredictedSample {
  long long index = 0;
  double time = 0;  ///< [min; sample index without recorded time]
  double predicted_um = 0, std_um = 0;
  bool has_measured = false;
  double measured_um = 0;  ///< on the model's zero
};

/// PredictRun on a run file streamed block by block (fixed memory): the same samples, statistics
/// and warnings. `sink` (optional) receives every sample in order (the CSV writer, a plot's
/// decimation). `scan` (optional): the file's ScanRun, when the caller has it (several passes
/// over one file scan it once).
PredictionSummary PredictFile(const DriftModel& model, const std::filesystem::path& run,
                              ReferenceMode reference = ReferenceMode::kRunStart,
                              const std::function<void(const PredictedSample&)>& sink = {},
                              const StreamProgress& progress = {}, const RunScan* scan = nullptr);

/// A run file named with its state, as the fit commands take them.
struct RunFile {
  std::filesystem::path path;
  RunState state = RunState::kUnknown;
};

/// The largest sample of training rows the fit's search holds [cells: rows x columns]: 2^20 cells
/// (8 MiB of values; 131,072 rows of 8 columns).
inline constexpr long long kSearchSampleCells = 1LL << 20;
/// ... and never more rows than this, nor fewer than 4,096 rows however wide the files.
inline constexpr long long kMaxSearchRows = 131072, kMinSearchRows = 4096;

/// FitDriftModel on run files streamed twice (issue 43).
///  1. One pass over every file collects an evenly thinned sample (every s-th row of each run from
///     its first, s a power of 2 doubled until the sample holds at most kSearchSampleCells cells,
///     so it lies between half and all of that), the exact sampling step of the logs (the median
///     step before each sampled row), and the sums and cross products of the rises and the error
///     over all rows (SelectionMoments).
///  2. When nothing was thinned (the runs are small), this is FitDriftModel on the runs read
///     whole: the same model, byte for byte. Otherwise the search runs on the sample: Miao et
///     al.'s selection with its similarity matrix, F test and dead/duplicate screen from the
///     moments of all rows and the grey grades on the sample; the candidates' validation, the lag
///     search and the elapsed-time constants (their shortest bound from the logs' own step) on
///     the sample.
///  3. The chosen model is refitted on all rows by a second pass (drift/regression.h
///     StreamingLeastSquares: coefficients, standard errors, residual std, R^2, training ranges;
///     a network keeps its trainbr fit on at most max_train_samples rows, its residual std and R^2
///     come from all rows). The model's notes say what was thinned.
/// InputError as FitDriftModel, and when a file changed between the passes.
FitReport FitFiles(const std::vector<RunFile>& files, const std::string& error_column,
                   const FitOptions& options, const StreamProgress& progress = {});

}  // namespace whirl::drift
