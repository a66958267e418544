#pragma once
// HTML reports of the drift module, for a process engineer: one index.html per directory with
// PNG plots (gnuplot, run through RunProgram without a shell; pngcairo, noenhanced titles, every
// user-supplied name through GnuplotString / HtmlEscape / Slug), the CSV each plot comes from
// and the gnuplot scripts, so anyone can re-plot. The directory follows core/output_dir.h's rule
// (new, empty or a whirl output; never a symbolic link) and the whole report is written
// all-or-nothing (gnuplot renders in its staging folder). If gnuplot is missing the CSVs, scripts
// and HTML are still written and `warnings` says the plots were skipped.
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/stream.h"

namespace whirl::drift {

/// One run shown by a model report: MAE [um] of the model and of the baselines -- no
/// compensation, a time-only warm-up fitted on the model's training runs (first order in the
/// time since the run's start, FitWarmUp), the "previous run": drift fit at its defaults redone on
/// the previous run shown (drift/fit.h PreviousRunOptions, the same as drift monitor --day's) --
/// NaN where a baseline does not exist for that run; `strongest` names the smallest
/// ("model", "none", "time only", "previous run"; empty when the run has no measured error).
struct ReportBaseline {
  std::string run;
  double model_mae_um = NAN, none_mae_um = NAN, time_only_mae_um = NAN, previous_run_mae_um = NAN;
  std::string strongest;
};

struct DriftReportResult {
  std::filesystem::path index_html;
  std::vector<std::filesystem::path> files;
  std::vector<std::string> warnings;
  std::vector<ReportBaseline> baselines;    ///< model reports: one per run shown
  std::vector<std::string> baseline_notes;  ///< why a baseline is missing
  std::vector<PredictionSummary> predictions;  ///< model reports: the model on each run shown
};

/// A fitted model (with its selection) applied to `runs`: the similarity matrix and lambda
/// levels, the grades and the chosen sensors, the coefficients, and per run the measured and
/// predicted error over time and the residual. Per run the model's prediction is evaluated sample
/// by sample into the per-sample CSV (written to disk as it is formatted), the plot's M4 rows
/// (core/decimate.h) and the running statistics; each baseline is one more such pass with its own
/// model (ReportBaseline), so the memory besides the runs given is independent of their length.
DriftReportResult WriteModelReport(const std::filesystem::path& dir, const FitReport& fit,
                                   const std::vector<Run>& runs,
                                   const std::vector<std::string>& provenance,
                                   const std::string& gnuplot = "gnuplot");
/// The same report on run files streamed block by block (drift/stream.h; any length): memory
/// independent of the rows shown (a block of rows, the plots' decimated rows, running sums), plus
/// the baselines' fits (FitFiles: the time-only warm-up on the training runs shown, drift fit's
/// defaults on the previous run). Its statistics equal the in-memory report's up to rounding
/// (ErrorStatsAccumulator); its models and plot rows are the same. `progress` (optional) hears
/// every pass over a file.
DriftReportResult WriteModelReport(const std::filesystem::path& dir, const FitReport& fit,
                                   const std::vector<RunFile>& runs,
                                   const std::vector<std::string>& provenance,
                                   const std::string& gnuplot = "gnuplot",
                                   const StreamProgress& progress = {});

/// A hold-out evaluation: per channel the measured error and every method's prediction over the
/// whole log prefix (train/test boundary marked) and the test residuals, with the table.
DriftReportResult WriteHoldoutReport(const std::filesystem::path& dir, const Run& log,
                                     const HoldoutResult& result,
                                     const std::vector<std::string>& provenance,
                                     const std::string& gnuplot = "gnuplot");

}  // namespace whirl::drift
