#pragma once
// The page every whirl report is: one stylesheet and one skeleton (doctype, charset, title,
// heading, provenance), so the workpiece, machine, drift, monitor and surface reports look alike
// and a change of style is made once. Used by the one renderer (core/report_render.h); reports
// build documents and never call these themselves. Everything user-supplied that reaches a page goes through
// HtmlEscape (core/safe_text.h); these helpers escape their arguments themselves.
#include <string>
#include <string_view>
#include <vector>

namespace whirl {

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
