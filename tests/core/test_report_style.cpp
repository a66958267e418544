// The shared report page (core/report_render.h) and plot styles (core/plot_style.h): every entry of
// the style table looks different from every other, the gnuplot style says what the table says,
// GroupSeries keeps its promises over many random sensor lists, the page skeleton escapes
// what it is given, and the one renderer (core/report_render.h) escapes every string of a
// document, draws each series in its look in the script and in the legend, and reads columns as
// numbers.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "core/plot_style.h"
#include "core/report_render.h"
#include "core/safe_text.h"

namespace whirl {
namespace {

TEST(PlotStyle, NoTwoSeriesLookAlike) {
  std::set<std::string_view> names;
  std::set<std::tuple<std::string_view, int, int>> looks;
  for (const SeriesStyle& s : SeriesStyles()) {
    EXPECT_TRUE(names.insert(s.name).second) << "twice in the table: " << s.name;
    EXPECT_TRUE(looks.insert({s.colour, s.dash, s.point}).second)
        << s.name << " looks like another series (" << s.colour << ", dash " << s.dash << ")";
    EXPECT_EQ(s.colour.size(), 7u) << s.name;
    EXPECT_EQ(s.colour.front(), '#') << s.name;
    EXPECT_GE(s.dash, 1) << s.name;
    EXPECT_LE(s.dash, 5) << s.name;
    EXPECT_GT(s.width, 0) << s.name;
  }
}

TEST(PlotStyle, GnuplotStyleIsTheTableEntry) {
  for (const SeriesStyle& s : SeriesStyles()) {
    const std::string with = GnuplotWith(s.name);
    EXPECT_NE(with.find("lc rgb '" + std::string(s.colour) + "'"), std::string::npos) << with;
    EXPECT_NE(with.find(" dt " + std::to_string(s.dash)), std::string::npos) << with;
    EXPECT_EQ(with.rfind(s.point ? "with linespoints " : "with lines ", 0), 0u) << with;
    if (s.point) {
      EXPECT_NE(with.find(" pt " + std::to_string(s.point)), std::string::npos) << with;
    }
  }
  // A name the table lacks gets a look no entry has.
  const std::string unknown = GnuplotWith("no such strategy");
  for (const SeriesStyle& s : SeriesStyles())
    EXPECT_EQ(unknown.find(std::string(s.colour)), std::string::npos) << s.name;
}

TEST(PlotStyle, GroupSeriesKeepsEveryNameOnceWithinTheLimitAndGroupsTogether) {
  std::mt19937 rng(7);
  const std::vector<std::string> prefixes = {"bed", "head", "z", "ambient", "coolant", "x"};
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = rng() % 30, max = 1 + rng() % 9;
    std::vector<std::string> names;
    for (std::size_t i = 0; i < n; ++i)
      names.push_back(prefixes[rng() % prefixes.size()] + "_s" + std::to_string(i) + "_C");
    const auto plots = GroupSeries(names, max);
    std::vector<int> seen(n, 0);
    std::map<std::string, std::set<std::size_t>> plots_of_prefix;
    std::map<std::string, std::size_t> count_of_prefix;
    for (const auto& name : names) ++count_of_prefix[name.substr(0, name.find('_'))];
    for (std::size_t p = 0; p < plots.size(); ++p) {
      EXPECT_FALSE(plots[p].empty());
      EXPECT_LE(plots[p].size(), max);
      for (std::size_t i : plots[p]) {
        ASSERT_LT(i, n);
        ++seen[i];
        plots_of_prefix[names[i].substr(0, names[i].find('_'))].insert(p);
      }
    }
    for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(seen[i], 1) << names[i];
    // A group that fits in one plot is in one plot; a larger one in as few as it needs.
    for (const auto& [prefix, count] : count_of_prefix)
      EXPECT_EQ(plots_of_prefix[prefix].size(), (count + max - 1) / max)
          << prefix << " (" << count << " series, " << max << " per plot)";
  }
  EXPECT_THROW(GroupSeries({"a"}, 0), std::invalid_argument);
}

TEST(PlotStyle, GroupSeriesOfThirteenMachineSensors) {
  // Worked by hand: 13 machine sensors (those of the retired closed-form machine), at most 8 per
  // plot; the bed and head groups stay whole.
  const std::vector<std::string> names = {
      "ambient_C",         "bed_headstock_C", "bed_middle_C",   "bed_tailstock_C", "head_motor_C",
      "head_bearing_C",    "head_housing_C",  "ring_gearbox_C", "coolant_tank_C",  "z_nut_C",
      "z_fixed_bearing_C", "z_motor_C",       "cabinet_C"};
  const std::vector<std::vector<std::size_t>> expected = {{0, 1, 2, 3, 4, 5, 6, 7},
                                                          {8, 9, 10, 11, 12}};
  EXPECT_EQ(GroupSeries(names, 8), expected);
}

TEST(HtmlPage, SkeletonEscapesTitleProvenanceLinksAndImages) {
  const std::string page = HtmlPageBegin("<b>x</b> & 'y'", {"cmd --name \"<script>\""}) +
                           HtmlLink("a'b.csv", "<i>") + HtmlImage("p'.png", "\"alt\"") +
                           HtmlPageEnd();
  EXPECT_EQ(page.find("<b>x"), std::string::npos);
  EXPECT_EQ(page.find("<script>"), std::string::npos);
  EXPECT_EQ(page.find("<i>"), std::string::npos);
  EXPECT_EQ(page.find("a'b.csv"), std::string::npos);
  EXPECT_NE(page.find("<title>&lt;b&gt;x&lt;/b&gt; &amp; &#39;y&#39;</title>"), std::string::npos);
  EXPECT_NE(page.find("<h1>&lt;b&gt;x"), std::string::npos);
  EXPECT_EQ(page.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(page.find("<meta charset='utf-8'>"), std::string::npos);
  EXPECT_EQ(page.substr(page.size() - HtmlPageEnd().size()), HtmlPageEnd());
  // The one stylesheet is in the page, and it wraps long lines of preformatted text.
  EXPECT_NE(page.find(std::string(ReportStylesheet())), std::string::npos);
  EXPECT_NE(ReportStylesheet().find("white-space:pre-wrap"), std::string::npos);
}

// A document with hostile text everywhere: the page holds it as text only, the script as
// single-quoted gnuplot strings only (a newline would end a command).
TEST(ReportRender, EveryStringOfADocumentIsEscaped) {
  const std::string hostile = "a'b\"c\\d\n<script>alert(1)</script>&";
  report::Document doc;
  doc.title = hostile;
  doc.provenance = {hostile};
  doc.Say(hostile, report::Tone::kWarn);
  doc.Add(report::Paragraph{{report::Link(hostile, hostile), report::Code(hostile)}});
  report::Table t;
  t.header = {hostile};
  t.rows = {{hostile}};
  t.series_rows = true;
  t.caption = hostile;
  doc.Add(t).Add(report::Preformatted{hostile});
  report::Panel p;
  p.title = p.xlabel = p.ylabel = hostile;
  p.tic_names = {hostile};
  p.series.push_back({hostile, -1, {report::Col(1), report::Col(2)}, report::SeriesKind::kLine,
                      "model", "", 1.5, false, hostile});
  report::Figure f;
  f.stem = "plot";
  f.title = hostile;
  f.panels = {p};
  doc.Add(f);
  const std::string html = report::RenderHtml(doc, {"plot"});
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_EQ(html.find("a'b"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt;&amp;"), std::string::npos);
  const std::string gp = report::GnuplotScript(f);
  EXPECT_EQ(gp.find("\n<script>"), std::string::npos);
  EXPECT_NE(gp.find("title " + GnuplotString(hostile)), std::string::npos) << gp;
  EXPECT_NE(gp.find(GnuplotString(hostile) + " using 1:2 "), std::string::npos) << gp;
  EXPECT_NE(gp.find("noenhanced"), std::string::npos);
}

// Each series is drawn in its look: the script's style is GnuplotWith, the legend's swatch the
// same colour with data-series naming the look; an untitled series has no legend entry; a
// missing picture gives a note and no legend.
TEST(ReportRender, SeriesLookTheSameInScriptAndLegend) {
  report::Figure f;
  f.stem = "lead";
  report::Panel p;
  for (const char* s : {"none", "traditional", "model"})
    p.series.push_back({"lead.csv", -1, {report::Col(1), report::Col(2)},
                        report::SeriesKind::kLine, s, "", 1.5, false, std::string(s) + " words"});
  p.series.push_back({"lead.csv", -1, {report::Col(1), report::Col(3)},
                      report::SeriesKind::kPoints, "", "#123456", 1.5, false, ""});
  f.panels = {p};
  report::Document doc;
  doc.Add(f);
  const std::string gp = report::GnuplotScript(f);
  const std::string html = report::RenderHtml(doc, {"lead"});
  for (const char* s : {"none", "traditional", "model"}) {
    EXPECT_NE(gp.find(GnuplotWith(s) + " title '" + s + " words'"), std::string::npos) << gp;
    const std::string entry = std::string("data-series='") + s + "' data-colour='" +
                              std::string(FindSeriesStyle(s)->colour) + "'";
    EXPECT_NE(html.find(entry), std::string::npos) << html;
  }
  EXPECT_NE(gp.find("lc rgb '#123456' notitle"), std::string::npos) << gp;
  EXPECT_EQ(html.find("#123456"), std::string::npos) << "an untitled series in the legend";
  EXPECT_NE(gp.find("unset key"), std::string::npos);  // the legend is the page's
  const std::string missing = report::RenderHtml(doc, {});
  EXPECT_EQ(missing.find("class='legend'"), std::string::npos);
  EXPECT_NE(missing.find("lead.png not rendered"), std::string::npos);
}

// Columns are numbers: $i, ($i+$p-$m)/d, and a filter on a column's value.
TEST(ReportRender, ColumnsAreGnuplotExpressionsOfNumbers) {
  report::Column c = report::Col(2, 60);
  c.plus = 4;
  c.minus = 5;
  report::Column f = report::Col(2);
  f.only_if_column = 3;
  f.only_if_value = 1;
  report::Panel p;
  p.series.push_back({"d.csv", 2, {report::Col(1), c}, report::SeriesKind::kLine, "", "#000000",
                      1, false, ""});
  p.series.push_back({"d.csv", -1, {report::Col(1), f}, report::SeriesKind::kPoints, "",
                      "#000000", 1, false, ""});
  report::Figure fig;
  fig.stem = "x";
  fig.panels = {p};
  const std::string gp = report::GnuplotScript(fig);
  EXPECT_NE(gp.find("'d.csv' index 2 using 1:(($2+$4-$5)/60) "), std::string::npos) << gp;
  EXPECT_NE(gp.find("'' using 1:($3==1?$2:1/0) "), std::string::npos) << gp;
}

// A band's edges are the prediction's column shifted by -sd and +sd; its legend entry says it
// is a band (data-kind), the line's that it is a line.
TEST(ReportRender, BandEdgesAreTheColumnShiftedBySd) {
  report::Panel p;
  p.series.push_back({"d.csv",
                      -1,
                      {report::Col(1, 60), report::Shifted(3, -1.5), report::Shifted(3, 2.25)},
                      report::SeriesKind::kBand,
                      "model",
                      "",
                      1.5,
                      false,
                      "model +- 1 sd"});
  p.series.push_back({"d.csv",
                      -1,
                      {report::Col(1, 60), report::Col(3)},
                      report::SeriesKind::kLine,
                      "model",
                      "",
                      1.5,
                      false,
                      "model"});
  report::Figure fig;
  fig.stem = "x";
  fig.panels = {p};
  report::Document doc;
  doc.Add(fig);
  const std::string gp = report::GnuplotScript(fig);
  EXPECT_NE(gp.find("'d.csv' using (($1)/60):($3-1.5):($3+2.25) with filledcurves"),
            std::string::npos)
      << gp;
  const std::string html = report::RenderHtml(doc, {"x"});
  EXPECT_NE(html.find("data-series='model' data-colour='#1f77b4' data-kind='band'"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("data-series='model' data-colour='#1f77b4' data-kind='line'"),
            std::string::npos)
      << html;
}

// An x axis left to gnuplot ends at the data (no extension to the next tic: a log ending at
// 520 min is not drawn to 540), at the end left open only, also with markers on the lines; a
// given range stays as given, and a map or a panel of markers only keeps gnuplot's choice; each
// panel clears the last one's first.
TEST(ReportRender, AnXAxisLeftToGnuplotEndsWhereTheDataEnd) {
  const auto panel = [](report::Range x, bool equal_axes) {
    report::Panel p;
    p.x = x;
    p.equal_axes = equal_axes;
    report::Series s;
    s.file = "d.csv";
    s.columns = {report::Col(1), report::Col(2)};
    p.series.push_back(s);
    return p;
  };
  report::Figure fig;
  fig.stem = "x";
  report::Panel points = panel({}, false);
  points.series.front().kind = report::SeriesKind::kLinePoints;
  report::Panel checks = panel({}, false);  // a log with markers of checks on it
  checks.series.push_back(checks.series.front());
  checks.series.back().kind = report::SeriesKind::kOpenPoints;
  fig.panels = {panel({}, false), panel({0, NAN}, false), panel({NAN, 5}, false),
                panel({0, 100}, false), panel({}, true), points, checks};
  const std::string gp = report::GnuplotScript(fig);
  std::vector<std::string> settings;  // what follows each panel's "set xrange"
  for (std::size_t at = gp.find("set autoscale x\nset xrange "); at != std::string::npos;
       at = gp.find("set autoscale x\nset xrange ", at + 1))
    settings.push_back(gp.substr(at, gp.find("set yrange", at) - at));
  ASSERT_EQ(settings.size(), 7u) << gp;
  EXPECT_EQ(settings[0], "set autoscale x\nset xrange [*:*]\nset autoscale xfix\n");
  EXPECT_EQ(settings[1], "set autoscale x\nset xrange [0:*]\nset autoscale xfixmax\n");
  EXPECT_EQ(settings[2], "set autoscale x\nset xrange [*:5]\nset autoscale xfixmin\n");
  EXPECT_EQ(settings[3], "set autoscale x\nset xrange [0:100]\n");
  EXPECT_EQ(settings[4], "set autoscale x\nset xrange [*:*]\n");
  EXPECT_EQ(settings[5], "set autoscale x\nset xrange [*:*]\n");  // markers only: room
  EXPECT_EQ(settings[6], "set autoscale x\nset xrange [*:*]\nset autoscale xfix\n");
}

// The header of a text column is left-aligned like its cells; a column of numbers stays
// right-aligned under its header.
TEST(ReportRender, TextColumnsAndTheirHeadersAreLeftAligned) {
  report::Table t;
  t.header = {"strategy", "within 1000 mm [um]", "ISO 3408-3 class", "note"};
  t.rows = {{"none", "12.5", "T7", "-"}, {"model", "-3.25", "P3", ""}};
  report::Document doc;
  doc.Add(t);
  const std::string html = report::RenderHtml(doc, {});
  // Column 3 of 4 is text: the table says so, the stylesheet left-aligns its cells and header.
  EXPECT_NE(html.find("<table class='l3'>"), std::string::npos) << html;
  EXPECT_NE(std::string(ReportStylesheet()).find(".l3 td:nth-child(3),.l3 th:nth-child(3)"),
            std::string::npos);
  report::Table numbers;
  numbers.rows = {{"none", "12.5", "-"}};
  report::Document plain;
  plain.Add(numbers);
  EXPECT_NE(report::RenderHtml(plain, {}).find("<table>"), std::string::npos);
}

// One sensor, one colour: the palette's colours differ, and the i-th series' colour is the
// palette's i-th whichever panel it is drawn in.
TEST(PlotStyle, PaletteColoursDifferAndFollowTheIndex) {
  const auto& palette = SeriesPalette();
  EXPECT_GE(palette.size(), 13u);  // the simulated machine's sensors, each its own
  EXPECT_EQ(std::set<std::string_view>(palette.begin(), palette.end()).size(), palette.size());
  for (std::size_t i = 0; i < 2 * palette.size(); ++i)
    EXPECT_EQ(PaletteColour(i), palette[i % palette.size()]);
}

}  // namespace
}  // namespace whirl
