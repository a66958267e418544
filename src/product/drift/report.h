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
};

/// A fitted model (with its selection) applied to `runs`: the similarity matrix and lambda
/// levels, the grades and the chosen sensors, the coefficients, and per run the measured and
/// predicted error over time and the residual.
DriftReportResult WriteModelReport(const std::filesystem::path& dir, const FitReport& fit,
                                   const std::vector<Run>& runs,
                                   const std::vector<std::string>& provenance,
                                   const std::string& gnuplot = "gnuplot");

/// A hold-out evaluation: per channel the measured error and every method's prediction over the
/// whole log prefix (train/test boundary marked) and the test residuals, with the table.
DriftReportResult WriteHoldoutReport(const std::filesystem::path& dir, const Run& log,
                                     const HoldoutResult& result,
                                     const std::vector<std::string>& provenance,
                                     const std::string& gnuplot = "gnuplot");

}  // namespace whirl::drift
