#pragma once
// The one renderer of every whirl report (core/report_document.h): the page as HTML with the one
// stylesheet and skeleton below (ReportStylesheet, HtmlPageBegin: the workpiece, machine, drift,
// monitor and surface reports look alike and a change of style is made once), each figure as a
// gnuplot script (<stem>.gp, kept beside its data so anyone can re-plot) rendered to <stem>.png
// by gnuplot (pngcairo, falling back to png; run through OutputDir::RunInStaging, an argument
// vector and no shell), and beside each picture its legend in HTML: one entry per titled
// series, drawn in the series' look (core/plot_style.h) with `data-series` (the look's key),
// `data-colour` and `data-kind` (line, band, points) attributes a test can read. The pictures
// carry no key of their own (it can neither cover the data nor be clipped); the scripts keep
// every series' title, so `set key` in a script brings it back. An x axis a panel leaves to
// gnuplot ends where its lines end (not at the next tic); a map or a panel of markers only keeps
// gnuplot's choice.
// Safety: every string of the document reaches the page through HtmlEscape and the scripts
// through GnuplotString (noenhanced); file names and hrefs are escaped as attributes; the columns
// are numbers. Without gnuplot (or with plots off), the page, data and scripts are still written
// and the result's warnings say so; the page shows them at its top.
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "core/output_dir.h"
#include "core/report_document.h"

namespace whirl {
// The page skeleton (used by the renderer; reports build documents and never call these).
/// The stylesheet of every report page: readable width, tables with a header row, the "load onto
/// the control" box (class `control`), warnings (class `warn`), small print (class `small`).
/// Nothing is wider than the page: images shrink to it, <pre> blocks wrap long lines (an NC line
/// of 300 characters stays on the page), a table wider than the page scrolls inside itself.
std::string_view ReportStylesheet();

/// The opening of a report page up to and including its <h1>: doctype, UTF-8, viewport, the
/// escaped `title` as <title> and <h1>, the stylesheet, then each `provenance` line (the command,
/// the model, the seed) escaped in small print.
std::string HtmlPageBegin(std::string_view title, const std::vector<std::string>& provenance = {});

/// The closing of a report page ("</body></html>").
std::string HtmlPageEnd();

/// <img src='file' alt='alt'> with both escaped; `file` is a name relative to the page.
std::string HtmlImage(std::string_view file, std::string_view alt);

/// <a href='href'>text</a> with both escaped; `href` is a path relative to the page.
std::string HtmlLink(std::string_view href, std::string_view text);
}  // namespace whirl

namespace whirl::report {

struct RenderOptions {
  bool plots = true;
  std::string gnuplot = "gnuplot";
  std::string page = "index.html";  ///< the page's file name in the output directory
};

struct RenderResult {
  bool plots_rendered = false;        ///< every figure was rendered (false when there are none)
  std::vector<std::string> warnings;  ///< e.g. "'gnuplot' not found: plots skipped"
};

/// Writes every figure's script (and, with gnuplot, its picture) and the page into `out` (not
/// committed: the caller adds its data files and commits). `warnings` given by the caller are
/// shown at the top of the page with the renderer's own, which are also returned.
RenderResult RenderReport(const Document& doc, OutputDir& out, const RenderOptions& options = {},
                          const std::vector<std::string>& warnings = {});

/// The page's HTML; `rendered` names the figures (stems) whose pictures exist.
std::string RenderHtml(const Document& doc, const std::set<std::string>& rendered,
                       const std::vector<std::string>& warnings = {});

/// The gnuplot script of one figure for `terminal` (e.g. "pngcairo"; size and font are added).
std::string GnuplotScript(const Figure& figure, const std::string& terminal = "pngcairo");

/// Every figure of the document, boxes included, in order.
std::vector<const Figure*> Figures(const Document& doc);

}  // namespace whirl::report
