#include "core/report_render.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "core/numbers.h"
#include "core/plot_style.h"
#include "core/run_program.h"
#include "core/safe_text.h"

namespace whirl {

std::string_view ReportStylesheet() {
  return "body{font-family:sans-serif;max-width:1100px;margin:1.5em auto;padding:0 1em;color:#222;"
         "line-height:1.4}\n"
         "h1{font-size:1.6em}h2{margin-top:1.6em;border-bottom:1px solid #ccc}\n"
         "table{border-collapse:collapse;margin:0.6em 0;display:block;overflow-x:auto;"
         "max-width:100%}\n"
         "td,th{border:1px solid #bbb;padding:3px 8px;text-align:right;vertical-align:top}\n"
         "td:first-child,th:first-child{text-align:left}th{background:#eee}\n"
         // A text column k (names, classes; TextColumns) of a table of class lk, header too.
         ".l2 td:nth-child(2),.l2 th:nth-child(2),.l3 td:nth-child(3),.l3 th:nth-child(3),"
         ".l4 td:nth-child(4),.l4 th:nth-child(4),.l5 td:nth-child(5),.l5 th:nth-child(5),"
         ".l6 td:nth-child(6),.l6 th:nth-child(6),.l7 td:nth-child(7),.l7 th:nth-child(7),"
         ".l8 td:nth-child(8),.l8 th:nth-child(8),.l9 td:nth-child(9),.l9 th:nth-child(9),"
         ".l10 td:nth-child(10),.l10 th:nth-child(10),.l11 td:nth-child(11),"
         ".l11 th:nth-child(11),.l12 td:nth-child(12),.l12 th:nth-child(12){text-align:left}\n"
         "tr.cls td{font-weight:bold}\n"
         ".small{font-size:0.85em;color:#555}.warn{color:#a00}\n"
         ".control{border:2px solid #2a6;background:#f3fbf5;padding:0.4em 1.2em 0.8em;"
         "margin:1em 0;border-radius:6px}\n"
         ".control h2{border:none;margin-top:0.5em}\n"
         "pre,code{font-family:monospace;font-size:0.9em}\n"
         "pre{background:#f6f6f6;padding:6px;white-space:pre-wrap;overflow-wrap:anywhere}\n"
         "img{max-width:100%;height:auto;border:1px solid #ddd;display:block;margin:0.5em 0}\n"
         "figure{margin:0.8em 0}\n"
         ".legend{list-style:none;padding:0;margin:0.2em 0 1em;columns:2 24em;font-size:0.9em}\n"
         ".legend li{break-inside:avoid;margin:0.1em 0}"
         ".legend svg{vertical-align:middle;margin-right:0.5em}\n";
}

std::string HtmlPageBegin(std::string_view title, const std::vector<std::string>& provenance) {
  std::string h =
      "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'>"
      "<meta name='viewport' content='width=device-width, initial-scale=1'><title>" +
      HtmlEscape(title) + "</title>\n<style>\n" + std::string(ReportStylesheet()) +
      "</style></head><body>\n<h1>" + HtmlEscape(title) + "</h1>\n";
  for (const auto& p : provenance) h += "<p class='small'>" + HtmlEscape(p) + "</p>\n";
  return h;
}

std::string HtmlPageEnd() { return "</body></html>\n"; }

std::string HtmlImage(std::string_view file, std::string_view alt) {
  return "<img src='" + HtmlEscape(file) + "' alt='" + HtmlEscape(alt) + "'>";
}

std::string HtmlLink(std::string_view href, std::string_view text) {
  return "<a href='" + HtmlEscape(href) + "'>" + HtmlEscape(text) + "</a>";
}

}  // namespace whirl

namespace whirl::report {

Span Text(std::string text) { return {Span::Kind::kText, std::move(text), {}}; }
Span Bold(std::string text) { return {Span::Kind::kBold, std::move(text), {}}; }
Span Code(std::string text) { return {Span::Kind::kCode, std::move(text), {}}; }
Span Link(std::string href, std::string text) {
  return {Span::Kind::kLink, std::move(text), std::move(href)};
}
Column Col(int index, double divide) {
  Column c;
  c.index = index;
  c.divide = divide;
  return c;
}
Column Shifted(int index, double add) {
  Column c;
  c.index = index;
  c.add = add;
  return c;
}
Series SdBand(std::string file, Column x, int y, double sd, std::string style, std::string title) {
  Series s;
  s.file = std::move(file);
  s.columns = {x, Shifted(y, -sd), Shifted(y, sd)};
  s.kind = SeriesKind::kBand;
  s.style = std::move(style);
  s.title = std::move(title);
  return s;
}

namespace {
// A block of `kind` holding `value` in its member `field`.
template <typename T>
Block Made(Block::Kind kind, T Block::*field, T value) {
  Block b;
  b.kind = kind;
  b.*field = std::move(value);
  return b;
}
Document& Append(Document* doc, Block b) {
  doc->blocks.push_back(std::move(b));
  return *doc;
}
}  // namespace

Block MakeBlock(Heading h) { return Made(Block::Kind::kHeading, &Block::heading, std::move(h)); }
Block MakeBlock(Paragraph p) {
  return Made(Block::Kind::kParagraph, &Block::paragraph, std::move(p));
}
Block MakeBlock(Table t) { return Made(Block::Kind::kTable, &Block::table, std::move(t)); }
Block MakeBlock(List l) { return Made(Block::Kind::kList, &Block::list, std::move(l)); }
Block MakeBlock(Preformatted p) {
  return Made(Block::Kind::kPreformatted, &Block::pre, std::move(p));
}
Block MakeBlock(Figure f) { return Made(Block::Kind::kFigure, &Block::figure, std::move(f)); }
Block MakeBlock(Box x) { return Made(Block::Kind::kBox, &Block::box, std::move(x)); }

Document& Document::Add(Heading h) { return Append(this, MakeBlock(std::move(h))); }
Document& Document::Add(Paragraph p) { return Append(this, MakeBlock(std::move(p))); }
Document& Document::Add(Table t) { return Append(this, MakeBlock(std::move(t))); }
Document& Document::Add(List l) { return Append(this, MakeBlock(std::move(l))); }
Document& Document::Add(Preformatted p) { return Append(this, MakeBlock(std::move(p))); }
Document& Document::Add(Figure f) { return Append(this, MakeBlock(std::move(f))); }
Document& Document::Add(Box b) { return Append(this, MakeBlock(std::move(b))); }
Document& Document::Add(const std::vector<Block>& more) {
  blocks.insert(blocks.end(), more.begin(), more.end());
  return *this;
}
Document& Document::Say(std::string text, Tone tone) {
  return Add(Paragraph{{Text(std::move(text))}, tone});
}

namespace {

namespace fs = std::filesystem;

// ---- gnuplot -------------------------------------------------------------------------------

// A column as gnuplot reads it: "3", "($1/60)", "($2-$5)", "($3==0?$2:1/0)".
std::string ColumnText(const Column& c) {
  std::string e = "$" + std::to_string(c.index);
  bool plain = true;
  if (c.plus > 0) {
    e += "+$" + std::to_string(c.plus);
    plain = false;
  }
  if (c.minus > 0) {
    e += "-$" + std::to_string(c.minus);
    plain = false;
  }
  if (c.divide != 1) {
    e = "(" + e + ")/" + FormatNumber(c.divide);
    plain = false;
  }
  if (c.add != 0) {
    e += (c.add > 0 ? "+" : "-") + FormatNumber(std::abs(c.add));
    plain = false;
  }
  if (c.only_if_column > 0) {
    e = "$" + std::to_string(c.only_if_column) + "==" + FormatNumber(c.only_if_value) + "?" + e +
        ":1/0";
    plain = false;
  }
  return plain ? std::to_string(c.index) : "(" + e + ")";
}

std::string Using(const Series& s) {
  std::string u;
  for (const Column& c : s.columns) u += (u.empty() ? "" : ":") + ColumnText(c);
  return u;
}

// The colour of a series: its look's, its own, or grey.
std::string Colour(const Series& s) {
  if (!s.style.empty()) {
    const SeriesStyle* st = FindSeriesStyle(s.style);
    return st ? std::string(st->colour) : "#aaaaaa";
  }
  return s.colour.empty() ? "#555555" : s.colour;
}

bool IsSurface(const Panel& p) {
  for (const Series& s : p.series)
    if (s.kind == SeriesKind::kMap || s.kind == SeriesKind::kContour) return true;
  return false;
}

// `bands`: how many bands the panel shades; the more, the lighter each (overlaps stay readable).
std::string With(const Series& s, bool surface, int bands) {
  const std::string lc = "lc rgb '" + Colour(s) + "'";
  const std::string nocontours = surface ? "nocontours " : "";
  switch (s.kind) {
    case SeriesKind::kLine: {
      std::string w = s.style.empty() ? "with lines " + lc + " lw " + FormatNumber(s.width) + " dt 1"
                                      : GnuplotWith(s.style);
      if (s.markers && w.rfind("with lines ", 0) == 0)
        w = "with linespoints " + w.substr(11) + " pt 6 ps 1.2 pn 40";
      return w;
    }
    case SeriesKind::kBand:
      return "with filledcurves fs transparent solid " +
             FormatNumber(bands <= 2 ? 0.15 : std::max(0.06, 0.3 / bands)) + " noborder " + lc;
    case SeriesKind::kPoints:
      return nocontours + "with points pt 7 ps 1.2 " + lc;
    case SeriesKind::kOpenPoints:
      return nocontours + "with points pt 6 ps 1.6 lw 1.5 " + lc;
    case SeriesKind::kLinePoints:
      return "with linespoints pt 5 lw 2 " + lc;
    case SeriesKind::kMap:
      return "with pm3d nocontours";
    case SeriesKind::kContour:
      return "nosurface with lines lc rgb '#202020'";
    case SeriesKind::kImage:
      return "with image";
  }
  return "";
}

std::string RangeText(const Range& r) {
  const auto end = [](double v) { return std::isfinite(v) ? FormatNumber(v) : std::string("*"); };
  return "[" + end(r.low) + ":" + end(r.high) + "]";
}

std::string Tics(const std::vector<std::string>& names) {
  std::string t;
  for (std::size_t i = 0; i < names.size(); ++i)
    t += (i ? ", " : "") + GnuplotString(names[i]) + " " + std::to_string(i);
  return "(" + t + ")";
}

// An x axis end chosen by gnuplot stays where the data end (gnuplot would extend it to the next
// tic: a log ending at 520 min drawn to 540) in a panel that draws lines or bands (a log over
// time; markers on it, e.g. checks, fall inside); maps, matrices and panels of markers only
// (which the axis would cut in half at its ends) keep gnuplot's own choice. The panel's settings
// clear it first ("set autoscale x"), so a panel never inherits it.
std::string XAutoscaleFix(const Panel& p, bool surface) {
  const bool lines = std::any_of(p.series.begin(), p.series.end(), [](const Series& x) {
    return x.kind == SeriesKind::kLine || x.kind == SeriesKind::kBand;
  });
  if (surface || !lines || p.equal_axes || !p.tic_names.empty()) return "";
  const bool low = !std::isfinite(p.x.low), high = !std::isfinite(p.x.high);
  if (low && high) return "set autoscale xfix\n";
  if (low) return "set autoscale xfixmin\n";
  if (high) return "set autoscale xfixmax\n";
  return "";
}

// The settings of one panel, each set or reset so that a panel never inherits the last one's.
std::string PanelSettings(const Panel& p, bool aligned) {
  std::ostringstream s;
  const bool surface = IsSurface(p);
  s << "unset arrow\nset title " << GnuplotString(p.title) << "\nset xlabel "
    << GnuplotString(p.xlabel) << "\nset ylabel " << GnuplotString(p.ylabel) << "\n";
  if (p.y2label.empty())
    s << "unset y2label\nunset y2tics\nset ytics mirror\n";
  else
    s << "set y2label " << GnuplotString(p.y2label) << "\nset y2tics\nset ytics nomirror\n";
  s << (p.y2_log ? "set logscale y2\n" : "unset logscale y2\n");
  s << "set autoscale x\nset xrange " << RangeText(p.x) << "\n" << XAutoscaleFix(p, surface)
    << "set yrange " << RangeText(p.y) << (p.y_reversed ? " reverse" : " noreverse") << "\n";
  s << (p.equal_axes ? "set size ratio -1\n" : "set size noratio\n");
  if (p.tic_names.empty())
    s << "set xtics autofreq norotate\nset ytics autofreq\n";
  else
    s << "set xtics " << Tics(p.tic_names) << " rotate by 90 right\nset ytics "
      << Tics(p.tic_names) << "\n";
  if (!p.cblabel.empty()) s << "set cblabel " << GnuplotString(p.cblabel) << "\n";
  if (aligned && !surface && !p.equal_axes)
    s << "set lmargin at screen 0.08\nset rmargin at screen 0.95\n";
  else
    s << "unset lmargin\nunset rmargin\n";
  for (double x : p.x_marks)
    s << "set arrow from " << FormatNumber(x) << ", graph 0 to " << FormatNumber(x)
      << ", graph 1 nohead dt 2 lc rgb '#555555'\n";
  for (double y : p.y2_marks)
    s << "set arrow from graph 0, second " << FormatNumber(y) << " to graph 1, second "
      << FormatNumber(y) << " nohead dt 2 lc rgb 'gray'\n";
  if (surface)
    s << "set view map\nset palette rgbformulae 33,13,10\nset contour base\n"
         "set cntrparam levels auto 12\nunset clabel\n";
  // Whitespace data (maps, matrices) unless the panel reads CSV.
  const bool csv = !p.series.empty() && p.series.front().file.size() > 4 &&
                   p.series.front().file.substr(p.series.front().file.size() - 4) == ".csv";
  s << (csv ? "set datafile separator ','\n" : "set datafile separator whitespace\n");
  return s.str();
}

std::string PlotCommand(const Panel& p) {
  const bool surface = IsSurface(p);
  std::ostringstream s;
  s << (surface ? "splot " : "plot ");
  if (p.series.empty()) return s.str() + "1/0 notitle\n";
  std::string last_file;
  const auto bands =
      static_cast<int>(std::count_if(p.series.begin(), p.series.end(),
                                     [](const Series& x) { return x.kind == SeriesKind::kBand; }));
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const Series& x = p.series[i];
    s << (i ? ", " : "") << (x.file == last_file ? "''" : GnuplotString(x.file));
    last_file = x.file;
    if (x.block >= 0) s << " index " << x.block;
    s << " using " << Using(x) << (x.right_axis ? " axes x1y2" : "") << " "
      << With(x, surface, bands) << " "
      << (x.title.empty() ? "notitle" : "title " + GnuplotString(x.title));
  }
  return s.str() + "\n";
}

std::string Terminal(const std::string& gnuplot) {
  return ProgramSucceeds({gnuplot, "-e", "set terminal pngcairo"}) ? "pngcairo" : "png";
}

// ---- HTML ----------------------------------------------------------------------------------

std::string SpansHtml(const std::vector<Span>& spans) {
  std::string h;
  for (const Span& s : spans) switch (s.kind) {
      case Span::Kind::kText:
        h += HtmlEscape(s.text);
        break;
      case Span::Kind::kBold:
        h += "<b>" + HtmlEscape(s.text) + "</b>";
        break;
      case Span::Kind::kCode:
        h += "<code>" + HtmlEscape(s.text) + "</code>";
        break;
      case Span::Kind::kLink:
        h += HtmlLink(s.href, s.text);
        break;
    }
  return h;
}

const char* ToneClass(Tone t) {
  switch (t) {
    case Tone::kSmall:
      return " class='small'";
    case Tone::kWarn:
      return " class='warn'";
    case Tone::kNormal:
      break;
  }
  return "";
}

// A cell that reads as a number ("3.2", "-5 %", "1e-3 um"); "" and "-" (nothing to show) do not.
bool Numeric(const std::string& text) {
  if (text.empty() || text == "-") return false;
  char* end = nullptr;
  std::strtod(text.c_str(), &end);
  return end != text.c_str();
}

// Per column: a text column (names, ISO classes, yes/no: some cell and no cell a number, or every
// cell marked left) is left-aligned, its header too; numbers stay right-aligned under theirs.
std::vector<bool> TextColumns(const Table& t) {
  std::size_t n = t.header.size();
  for (const auto& row : t.rows) n = std::max(n, row.size());
  std::vector<bool> text(n, false);
  for (std::size_t c = 0; c < n; ++c) {
    bool any = false, number = false, left = true;
    for (const auto& row : t.rows) {
      if (c >= row.size() || row[c].colspan > 1) continue;
      const std::string& x = row[c].text;
      any = any || (!x.empty() && x != "-");
      number = number || Numeric(x);
      left = left && row[c].left;
    }
    text[c] = any && (!number || left);
  }
  return text;
}

// The table's classes: "series" (Table::series_rows) and "lk" for each text column k (1-based,
// 2..12; the stylesheet left-aligns its cells and header; the first column is left anyway).
std::string TableClasses(const Table& t) {
  std::string c = t.series_rows ? "series" : "";
  const std::vector<bool> text = TextColumns(t);
  for (std::size_t k = 1; k < text.size() && k < 12; ++k)
    if (text[k]) c += (c.empty() ? "l" : " l") + std::to_string(k + 1);
  return c.empty() ? "" : " class='" + c + "'";
}

std::string TableHtml(const Table& t) {
  std::ostringstream h;
  h << "<table" << TableClasses(t) << ">";
  if (!t.header.empty()) {
    h << "<tr>";
    for (const auto& c : t.header) h << "<th>" << HtmlEscape(c) << "</th>";
    h << "</tr>";
  }
  h << "\n";
  for (std::size_t r = 0; r < t.rows.size(); ++r) {
    bool bold = false;
    for (std::size_t k : t.highlight) bold = bold || k == r;
    h << "<tr" << (bold ? " class='cls'" : "") << ">";
    for (std::size_t c = 0; c < t.rows[r].size(); ++c) {
      const Cell& cell = t.rows[r][c];
      h << "<td";
      if (c == 0 && t.series_rows && !cell.not_plotted) h << " data-series='" << HtmlEscape(cell.text) << "'";
      if (cell.colspan > 1) h << " colspan='" << cell.colspan << "'";
      if (cell.left) h << " style='text-align:left'";
      h << ">" << HtmlEscape(cell.text) << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</table>\n";
  if (!t.caption.empty()) h << "<p class='small'>" << HtmlEscape(t.caption) << "</p>\n";
  return h.str();
}

// SVG dash arrays of gnuplot's dash types 1..5 at a line width of about 2.
const char* DashArray(int dash) {
  switch (dash) {
    case 2:
      return "8 4";
    case 3:
      return "2 3";
    case 4:
      return "8 3 2 3";
    case 5:
      return "8 3 2 3 2 3";
    default:
      return "";
  }
}

// What a legend entry draws: "band" (a +-1 sd region), "points", or "line" (lines, maps).
const char* LegendKind(SeriesKind k) {
  switch (k) {
    case SeriesKind::kBand:
      return "band";
    case SeriesKind::kPoints:
    case SeriesKind::kOpenPoints:
      return "points";
    default:
      return "line";
  }
}

// One legend entry: a swatch in the series' look and its words, with data-series (the look),
// data-colour and data-kind (LegendKind) for a test to read.
std::string LegendEntry(const Series& s) {
  const std::string colour = Colour(s);
  int dash = 1;
  double width = s.width;
  int point = 0;
  if (!s.style.empty()) {
    const SeriesStyle* st = FindSeriesStyle(s.style);
    dash = st ? st->dash : 3;
    width = st ? st->width : 1.5;
    point = st ? st->point : 0;
  }
  std::ostringstream h;
  h << "<li";
  if (!s.style.empty()) h << " data-series='" << HtmlEscape(s.style) << "'";
  h << " data-colour='" << HtmlEscape(colour) << "' data-kind='" << LegendKind(s.kind)
    << "'><svg width='40' height='12' aria-hidden='true'>";
  switch (s.kind) {
    case SeriesKind::kBand:
      h << "<rect x='0' y='1' width='40' height='10' fill='" << colour
        << "' fill-opacity='0.25'/>";
      break;
    case SeriesKind::kPoints:
    case SeriesKind::kOpenPoints:
      h << "<circle cx='20' cy='6' r='4' stroke='" << colour << "' fill='"
        << (s.kind == SeriesKind::kPoints ? colour : "none") << "'/>";
      break;
    default:
      h << "<line x1='0' y1='6' x2='40' y2='6' stroke='" << colour << "' stroke-width='"
        << FormatNumber(std::max(1.0, width)) << "'";
      if (*DashArray(dash)) h << " stroke-dasharray='" << DashArray(dash) << "'";
      h << "/>";
      if (point || s.markers)
        h << "<circle cx='20' cy='6' r='3.5' stroke='" << colour << "' fill='none'/>";
  }
  h << "</svg>" << HtmlEscape(s.title) << "</li>\n";
  return h.str();
}

std::string FigureHtml(const Figure& f, const std::set<std::string>& rendered) {
  if (rendered.count(f.stem) == 0)
    return "<p class='warn'>Plot " + HtmlEscape(f.stem) + ".png not rendered (see the warnings; " +
           HtmlLink(f.stem + ".gp", f.stem + ".gp") + " draws it).</p>\n";
  std::string legend;
  std::set<std::string> seen;
  for (const Panel& p : f.panels)
    for (const Series& s : p.series)
      if (!s.title.empty() && seen.insert(s.style + "\n" + s.title).second)
        legend += LegendEntry(s);
  return "<figure id='fig-" + HtmlEscape(f.stem) + "'>" + HtmlImage(f.stem + ".png", f.alt) +
         (legend.empty() ? "" : "<ul class='legend'>\n" + legend + "</ul>") + "</figure>\n";
}

std::string BlocksHtml(const std::vector<Block>& blocks, const std::set<std::string>& rendered) {
  std::string h;
  for (const Block& b : blocks) switch (b.kind) {
      case Block::Kind::kHeading: {
        const std::string tag = b.heading.level >= 3 ? "h3" : "h2";
        h += "<" + tag +
             (b.heading.id.empty() ? "" : " id='" + HtmlEscape(b.heading.id) + "'") + ">" +
             HtmlEscape(b.heading.text) + "</" + tag + ">\n";
        break;
      }
      case Block::Kind::kParagraph:
        h += std::string("<p") + ToneClass(b.paragraph.tone) + ">" +
             SpansHtml(b.paragraph.spans) + "</p>\n";
        break;
      case Block::Kind::kTable:
        h += TableHtml(b.table);
        break;
      case Block::Kind::kList:
        h += std::string("<ul") + ToneClass(b.list.tone) + ">\n";
        for (const auto& item : b.list.items) h += "<li>" + SpansHtml(item) + "</li>\n";
        h += "</ul>\n";
        break;
      case Block::Kind::kPreformatted:
        h += "<pre>" + HtmlEscape(b.pre.text) + "</pre>\n";
        break;
      case Block::Kind::kFigure:
        h += FigureHtml(b.figure, rendered);
        break;
      case Block::Kind::kBox:
        h += "<section class='control'" +
             (b.box.id.empty() ? std::string() : " id='" + HtmlEscape(b.box.id) + "'") + ">\n" +
             BlocksHtml(b.box.blocks, rendered) + "</section>\n";
        break;
    }
  return h;
}

void CollectFigures(const std::vector<Block>& blocks, std::vector<const Figure*>* out) {
  for (const Block& b : blocks) {
    if (b.kind == Block::Kind::kFigure) out->push_back(&b.figure);
    if (b.kind == Block::Kind::kBox) CollectFigures(b.box.blocks, out);
  }
}

}  // namespace

std::string GnuplotScript(const Figure& f, const std::string& terminal) {
  std::ostringstream s;
  const bool cairo = terminal == "pngcairo";
  s << "# gnuplot script written by whirl; re-run with: gnuplot " << f.stem << ".gp\n"
    << "# The report's page shows the legend; 'set key' before a plot draws it here too.\n"
    << "set terminal " << terminal << " size " << f.width_px << "," << f.height_px
    << (cairo ? " font 'Sans,10'" : "") << " noenhanced\nset output "
    << GnuplotString(f.stem + ".png") << "\nset datafile commentschars '#'\nset grid\nunset key\n";
  const bool multi = f.panels.size() > 1;
  if (multi) {
    const int cols = std::max(1, f.columns);
    const int rows = static_cast<int>((f.panels.size() + cols - 1) / cols);
    s << "set multiplot layout " << rows << "," << cols << " title " << GnuplotString(f.title)
      << "\n";
  }
  for (const Panel& p : f.panels) {
    Panel shown = p;
    if (!multi && shown.title.empty()) shown.title = f.title;
    s << PanelSettings(shown, f.columns <= 1) << PlotCommand(shown);
  }
  if (multi) s << "unset multiplot\n";
  s << "set output\n";
  return s.str();
}

std::vector<const Figure*> Figures(const Document& doc) {
  std::vector<const Figure*> out;
  CollectFigures(doc.blocks, &out);
  return out;
}

std::string RenderHtml(const Document& doc, const std::set<std::string>& rendered,
                       const std::vector<std::string>& warnings) {
  std::string h = HtmlPageBegin(doc.title, doc.provenance);
  for (const auto& w : warnings) h += "<p class='warn'>warning: " + HtmlEscape(w) + "</p>\n";
  return h + BlocksHtml(doc.blocks, rendered) + HtmlPageEnd();
}

RenderResult RenderReport(const Document& doc, OutputDir& out, const RenderOptions& o,
                          const std::vector<std::string>& warnings) {
  RenderResult r;
  const std::vector<const Figure*> figures = Figures(doc);
  const bool gnuplot =
      o.plots && !figures.empty() && !o.gnuplot.empty() && ProgramSucceeds({o.gnuplot, "--version"});
  if (o.plots && !figures.empty() && !gnuplot)
    r.warnings.push_back("'" + o.gnuplot +
                         "' not found: plots skipped (install gnuplot-nox, e.g. scripts/setup.sh); "
                         "the page, the data and the .gp scripts are written");
  const std::string terminal = gnuplot ? Terminal(o.gnuplot) : "pngcairo";
  std::set<std::string> rendered;
  for (const Figure* f : figures) {
    out.Add(f->stem + ".gp", GnuplotScript(*f, terminal));
    if (!gnuplot) continue;
    // gnuplot never sees the output directory: it renders in the staging folder.
    const std::string png = f->stem + ".png", log = f->stem + ".gp.log";
    const int rc = out.RunInStaging({o.gnuplot, f->stem + ".gp"}, log, {png});
    std::error_code ec;
    const fs::path staged = out.Staging() / png;
    if (rc == 0 && fs::is_regular_file(staged, ec) && fs::file_size(staged, ec) > 0) {
      out.AddStaged(png);
      rendered.insert(f->stem);
    } else {
      out.AddProgramLog(log);
      r.warnings.push_back("gnuplot failed on " + (out.path() / (f->stem + ".gp")).string() +
                           " (exit " + std::to_string(rc) + ", see " + log + "): " + png +
                           " not drawn");
    }
  }
  r.plots_rendered = gnuplot && rendered.size() == figures.size();
  std::vector<std::string> shown = warnings;
  shown.insert(shown.end(), r.warnings.begin(), r.warnings.end());
  out.Add(o.page, RenderHtml(doc, rendered, shown));
  return r;
}

}  // namespace whirl::report
