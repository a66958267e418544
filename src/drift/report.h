#pragma once
// HTML reports of the drift module, for a process engineer: one index.html per directory with
// PNG plots (gnuplot, run through RunProgram without a shell; pngcairo, noenhanced titles, every
// user-supplied name through GnuplotString / HtmlEscape / Slug), the CSV each plot comes from
// and the gnuplot scripts, so anyone can re-plot. The directory follows core/output_dir.h's rule
// (new, empty or a whirl output; never a symbolic link) and the whole report is written
// all-or-nothing (gnuplot renders in its staging folder). If gnuplot is missing the CSVs, scripts
// and HTML are still written and `warnings` says the plots were skipped.
#include <filesystem>
#include <string>
#include <vector>

#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"

namespace whirl::drift {

struct DriftReportResult {
  std::filesystem::path index_html;
  std::vector<std::filesystem::path> files;
  std::vector<std::string> warnings;
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
