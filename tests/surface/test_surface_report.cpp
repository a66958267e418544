// The HTML page and gnuplot script of a surface fit: hostile user strings stay text.
#include <gtest/gtest.h>

#include <filesystem>

#include "core/atomic_file.h"
#include "core/run_program.h"
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

}  // namespace
}  // namespace whirl::surface
