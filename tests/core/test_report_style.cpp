// The shared report page (core/html_page.h) and plot styles (core/plot_style.h): every entry of
// the style table looks different from every other, the gnuplot style says what the table says,
// GroupSeries keeps its promises over many random sensor lists, and the page skeleton escapes
// what it is given.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "core/html_page.h"
#include "core/plot_style.h"

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

}  // namespace
}  // namespace whirl
