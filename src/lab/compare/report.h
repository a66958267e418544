#pragma once
// The report a process engineer opens after a comparison, built as a report document
// (core/report_document.h) and rendered by core/report_render.h: one page (index.html) that opens
// with the "load onto the control" box (plan/load.h LoadBox: setting data, programs,
// prerequisites, what to run after an abort), then per screw the metrics of every strategy
// (kStrategies) with the ISO 3408-3 class reached and how much less the model leaves, the
// elongation curve (simulated truth, the prediction with its +-1 sd band, i.e. the arctangent
// curves of the features at mean -+ 1 sd, and each strategy's compensation with the plan's
// compensation points), the travel deviation of every strategy along the thread (whole thread,
// and the first 1000 mm where the transient lives), each plot in two panels (the model with
// ramp, traditional and regression; the model with the history rules class, table, nearest),
// plus the CSV files every plot comes from and report.json. Each strategy has one colour and
// dash in every plot and legend (core/plot_style.h).
// Every plotted prediction has its +-1 sd band, from training data only (never from the screw
// being cut; ScrewComparison::band_sd_um): the model's is the prediction's (elongation: the band
// curves; travel deviation: the deviation had the plan been made from either band curve); a
// baseline's (ramp, traditional, regression, class, table, nearest) is its rule's leave-one-out
// mean relative error on the past screws times its plateau: its compensation times 1 -+ that
// error in the elongation plot, its curve -+ that many um in the travel-deviation plots
// (core/report_document.h SdBand, as the machine report's bands).
//
// Plots: gnuplot (Debian package gnuplot-nox), see core/report_render.h; without it the page,
// the CSVs and the scripts are still written and ReportResult::warnings says the plots were
// skipped. All-or-nothing: every file is collected by core/output_dir.h's OutputDir (gnuplot
// renders in its staging folder) and committed at once; a failure leaves no new file and the
// previous report intact. The directory follows OutputDir's rule: new, empty or a whirl output
// (never a symbolic link); files of an earlier report that this one does not write are removed.
// Safe with any screw name: the document holds plain text, the renderer escapes it; file names
// are Slugs.
#include <filesystem>
#include <string>
#include <vector>

#include "compare/compare.h"
#include "plan/load.h"

namespace whirl::compare {

struct ReportOptions {
  std::string title = "whirl: lead error with and without thermal-elongation compensation";
  /// Lines shown under the title and written as '#' comments into every CSV (command, seed, model).
  std::vector<std::string> provenance;
  /// Render PNGs with gnuplot (false: data, scripts and HTML only).
  bool plots = true;
  std::string gnuplot_command = "gnuplot";
  /// Extra notes shown at the top of the page (e.g. how the new-type screw was defined).
  std::vector<std::string> notes;
  /// The "load onto the control" box, one entry per comparison in the same order (heading and
  /// plan are taken from the comparison): the programs and PLC table written with the report
  /// (links relative to `dir`), the prerequisites, the call order, what to run after an abort.
  /// Missing entries: the box shows the plan's setting data and says that `whirl plan` writes
  /// the programs.
  std::vector<plan::ControlLoad> control;
  /// Where the history rules' past screws come from (e.g. "table.csv (24 screws)"), stated in
  /// "How to read this page"; empty: the page points to the lines under the title.
  std::string history;
};

struct ReportResult {
  std::filesystem::path index_html;
  std::vector<std::filesystem::path> files;  ///< every file written
  bool plots_rendered = false;
  std::vector<std::string> warnings;  ///< e.g. "gnuplot not found: plots skipped"
};

/// Writes the report for one or more screws into `dir` (created if missing). InputError if the
/// directory cannot be created or a file cannot be written; a failing gnuplot is a warning.
ReportResult WriteReport(const std::filesystem::path& dir,
                         const std::vector<ScrewComparison>& comparisons,
                         const ReportOptions& options = {});

/// Plain-text metrics table of one comparison (for the terminal): the metrics of every strategy,
/// the ISO class reached and how much less the model leaves than each.
std::string FormatComparisonTable(const ScrewComparison& c);

/// File-name stem for a screw name: lower case letters, digits, '-' and '_' only, at most 64
/// characters, never empty ("screw").
std::string Slug(const std::string& name);

}  // namespace whirl::compare
