// The HTML page and gnuplot script of a surface fit: hostile user strings stay text; the cubic /
// B-spline comparison is a table of its figures.
#include <gtest/gtest.h>

#include <filesystem>
#include <tuple>

#include "core/atomic_file.h"
#include "core/numbers.h"
#include "core/run_program.h"
#include "core/safe_text.h"
#include "surface/report.h"
#include "synthetic/surface.h"
#include "support/scratch_dir.h"

namespace whirl::surface {
namespace {

namespace fs = std::filesystem;

TEST(SurfaceReport, HostileTitleAndProvenanceStayText) {
  const fs::path dir = whirl::test::ScratchDir() / "whirl_surface_report_test";
  fs::remove_all(dir);
  synthetic::SyntheticOptions s;
  const SurfaceFit fit = FitSurface(synthetic::SyntheticPoints(s), {Method::kBspline, 3});
  const MethodComparison choice = CompareMethods(fit.points);
  SurfaceReportOptions o;
  o.title = "it's \\ a \"table\"\nset output '/tmp/pwned'\n<script>alert(1)</script>";
  o.provenance = {"points <b>x</b>.csv"};
  o.plots = ProgramSucceeds({"gnuplot", "--version"});
  const auto r = WriteSurfaceReport(dir, fit, &choice, {}, o);
  const std::string html = ReadTextFile(r.index_html);
  EXPECT_EQ(html.find("<script>"), std::string::npos);
  EXPECT_NE(html.find("&lt;script&gt;"), std::string::npos);
  EXPECT_EQ(html.find("<b>x</b>"), std::string::npos);
  const std::string gp = ReadTextFile(dir / "map.gp");
  // The title is one single-quoted gnuplot string: quote doubled, newline gone.
  EXPECT_NE(gp.find("set title 'it''s \\ a \"table\" set output ''/tmp/pwned'' <script>"),
            std::string::npos)
      << gp;
  EXPECT_EQ(gp.find("\nset output '/tmp/pwned'"), std::string::npos);
  if (o.plots) {
    EXPECT_TRUE(r.plot_rendered) << (r.warnings.empty() ? "" : r.warnings[0]);
    EXPECT_TRUE(fs::exists(dir / "map.png"));
    EXPECT_FALSE(fs::exists(dir / "map.png.tmp"));
  } else {
    GTEST_SKIP() << "gnuplot not installed: page checked, map not rendered";
  }
  EXPECT_FALSE(fs::exists("/tmp/pwned"));
  fs::remove_all(dir);
}

// The comparison of the two methods (choice.h) is a table, not preformatted text: one row per
// method with its leave-one-out figures, the recommended one in bold, the reason below.
TEST(SurfaceReport, MethodComparisonIsATableOfItsFigures) {
  const fs::path dir = whirl::test::ScratchDir() / "whirl_surface_report_choice";
  fs::remove_all(dir);
  synthetic::SyntheticOptions s;
  const SurfaceFit fit = FitSurface(synthetic::SyntheticPoints(s), {Method::kCubic, 3});
  const MethodComparison c = CompareMethods(fit.points);
  ASSERT_TRUE(c.cubic_available && c.bspline_available);
  SurfaceReportOptions o;
  o.plots = false;
  const std::string html = ReadTextFile(WriteSurfaceReport(dir, fit, &c, {}, o).index_html);
  EXPECT_EQ(html.find("<pre>"), std::string::npos) << html;
  const auto row = [&html](const std::string& method) {
    const std::size_t at = html.find("<td>" + method + "</td>");
    if (at == std::string::npos) return std::string();
    const std::size_t tr = html.rfind("<tr", at);
    return html.substr(tr, html.find("</tr>", at) - tr);
  };
  const auto cell = [](double um) { return "<td>" + FormatDecimals(um, 3) + "</td>"; };
  for (const auto& [name, all, common] :
       {std::tuple{ToString(Method::kCubic), c.cubic_loo, c.cubic_loo_common},
        std::tuple{ToString(Method::kBspline), c.bspline_loo, c.bspline_loo_common}}) {
    const std::string r = row(name);
    ASSERT_FALSE(r.empty()) << name;
    EXPECT_NE(r.find("<td>" + std::to_string(all.count) + "</td>" + cell(all.rms_um) +
                     cell(all.max_abs_um) + cell(common.rms_um) + cell(common.max_abs_um)),
              std::string::npos)
        << r;
    EXPECT_EQ(r.rfind("<tr class='cls'>", 0) == 0, name == ToString(c.recommended)) << r;
  }
  EXPECT_NE(html.find(HtmlEscape(c.reason)), std::string::npos);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace whirl::surface
