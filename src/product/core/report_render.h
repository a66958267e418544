#pragma once
// The one renderer of every whirl report (core/report_document.h): the page as HTML with the one
// stylesheet of core/html_page.h, each figure as a gnuplot script (<stem>.gp, kept beside its
// data so anyone can re-plot) rendered to <stem>.png by gnuplot (pngcairo, falling back to png;
// run through OutputDir::RunInStaging, an argument vector and no shell), and beside each picture
// its legend in HTML: one entry per titled series, drawn in the series' look (core/plot_style.h)
// with `data-series` (the look's key) and `data-colour` attributes a test can read. The pictures
// carry no key of their own (it can neither cover the data nor be clipped); the scripts keep
// every series' title, so `set key` in a script brings it back.
// Safety: every string of the document reaches the page through HtmlEscape and the scripts
// through GnuplotString (noenhanced); file names and hrefs are escaped as attributes; the columns
// are numbers. Without gnuplot (or with plots off), the page, data and scripts are still written
// and the result's warnings say so; the page shows them at its top.
#include <set>
#include <string>
#include <vector>

#include "core/output_dir.h"
#include "core/report_document.h"

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
