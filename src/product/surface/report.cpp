#include "surface/report.h"

#include <cmath>
#include <sstream>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/html_page.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/run_program.h"
#include "core/safe_text.h"

namespace whirl::surface {
namespace fs = std::filesystem;
namespace {

// gnuplot data: 10 significant digits.
std::string G10(double x) { return FormatSignificant(x, 10); }

std::string GridData(const SurfaceFit& fit, int n) {
  const Bounds& b = fit.surface.bounds;
  std::ostringstream s;
  s << "# x_mm y_mm error_um: the " << ToString(fit.surface.method) << " surface on a " << n
    << " x " << n << " map\n";
  for (int i = 0; i < n; ++i) {
    const double y = b.y_min_mm + (b.y_max_mm - b.y_min_mm) * i / (n - 1);
    for (int j = 0; j < n; ++j) {
      const double x = b.x_min_mm + (b.x_max_mm - b.x_min_mm) * j / (n - 1);
      s << G10(x) << ' ' << G10(y) << ' ' << G10(fit.surface.Evaluate(x, y)) << '\n';
    }
    s << '\n';
  }
  return s.str();
}

std::string PointsData(const SurfaceFit& fit) {
  std::ostringstream s;
  s << "# x_mm y_mm error_um: the measured points\n";
  for (const auto& p : fit.points)
    s << G10(p.x_mm) << ' ' << G10(p.y_mm) << ' ' << G10(p.error_um) << '\n';
  return s.str();
}

std::string MapScript(const SurfaceReportOptions& o, const std::string& terminal,
                      const std::string& subtitle) {
  std::ostringstream s;
  s << "# gnuplot script written by whirl surface; re-run with: gnuplot map.gp\n"
    << "set terminal " << terminal << "\n"
    << "set output 'map.png'\n"
    << "set title " << GnuplotString(o.title + ": " + subtitle) << " noenhanced\n"
    << "set xlabel 'X [mm]'\nset ylabel 'Y [mm]'\nset cblabel 'thermal error [um]'\n"
    << "set view map\nset size ratio -1\nset palette rgbformulae 33,13,10\n"
    << "set contour base\nset cntrparam levels auto 12\nunset clabel\n"
    << "unset key\n"
    << "set datafile separator whitespace\n"
    << "splot 'surface_grid.dat' using 1:2:3 with pm3d nocontours notitle, \\\n"
    << "  '' using 1:2:3 nosurface with lines lc rgb '#202020' notitle, \\\n"
    << "  'points.dat' using 1:2:3 nocontours with points pt 7 ps 1.3 "
       "lc rgb 'black' notitle\n"
    << "set output\n";
  return s.str();
}

std::string Terminal(const std::string& gnuplot) {
  const bool cairo = ProgramSucceeds({gnuplot, "-e", "set terminal pngcairo"});
  return cairo ? "pngcairo size 1000,700 font 'Sans,10' noenhanced"
               : "png size 1000,700 noenhanced";
}

// Renders map.gp in the output directory's staging folder; adds map.png to the output.
bool Render(OutputDir& out, const SurfaceReportOptions& o, SurfaceReportResult& r) {
  if (!ProgramSucceeds({o.gnuplot_command, "--version"})) {
    r.warnings.push_back("gnuplot ('" + o.gnuplot_command + "') not found: map skipped");
    return false;
  }
  const int rc = out.RunInStaging({o.gnuplot_command, "map.gp"}, "gnuplot.log", {"map.png"});
  const fs::path stage = out.Staging();
  std::error_code ec;
  if (rc != 0 || !fs::is_regular_file(stage / "map.png", ec)) {
    out.AddProgramLog("gnuplot.log");
    r.warnings.push_back("gnuplot failed (exit " + std::to_string(rc) +
                         "), see gnuplot.log: map skipped");
    return false;
  }
  out.AddStaged("map.png");
  return true;
}

std::string SummaryHtml(const SurfaceFit& f) {
  const ErrorStats res = StatsOf(f.residual_um), loo = StatsOf(f.loo_error_um);
  std::ostringstream h;
  h << "<table><tr><th>method</th><td>" << ToString(f.surface.method);
  if (f.surface.method == Method::kBspline) h << ", degree " << f.surface.bspline.degree;
  h << "</td></tr>\n<tr><th>points</th><td>" << f.points.size() << "</td></tr>\n"
    << "<tr><th>condition number</th><td>" << FormatDecimalsOr(f.condition_number, 1, "-");
  if (f.surface.method == Method::kCubic)
    h << " (normalized coordinates; " << FormatSignificant(f.condition_number_mm, 3)
      << " in raw mm)";
  h << "</td></tr>\n<tr><th>residual RMS / max</th><td>" << FormatDecimalsOr(res.rms_um, 3, "-")
    << " / " << FormatDecimalsOr(res.max_abs_um, 3, "-") << " um</td></tr>\n"
    << "<tr><th>leave-one-out RMS / max</th><td>" << FormatDecimalsOr(loo.rms_um, 3, "-") << " / "
    << FormatDecimalsOr(loo.max_abs_um, 3, "-") << " um over " << loo.count
    << " points</td></tr>\n</table>\n";
  if (f.surface.method == Method::kCubic) {
    const auto a = f.surface.cubic.CoefficientsMm();
    h << "<p>dE = a0 + a1 X + a2 Y + a3 X&sup2; + a4 XY + a5 Y&sup2; + a6 X&sup3; + a7 X&sup2;Y + "
         "a8 XY&sup2; + a9 Y&sup3; (um, X and Y in mm)</p>\n<table><tr>";
    for (int k = 0; k < kCubicTerms; ++k) h << "<th>a" << k << "</th>";
    h << "</tr><tr>";
    for (int k = 0; k < kCubicTerms; ++k) {
      h << "<td>" << FormatExponent(a[k], 4) << "</td>";
    }
    h << "</tr></table>\n";
  }
  return h.str();
}

std::string LinesHtml(const std::vector<AxisLine>& lines) {
  if (lines.empty()) return "";
  std::ostringstream h;
  h << "<h2>840D: the least-squares line per axis (what temperature compensation can apply)</h2>\n"
       "<table><tr><th>axis</th><th>along</th><th>SD43900 [mm]</th><th>SD43910</th>"
       "<th>SD43920 [mm]</th><th>error max / RMS [um]</th><th>left by the line max / RMS "
       "[um]</th></tr>\n";
  for (const auto& l : lines)
    h << "<tr><td>" << HtmlEscape(l.options.axis) << "</td><td>" << l.options.along << "</td><td>"
      << FormatDecimalsOr(l.sd43900_mm, 6, "-") << "</td><td>"
      << FormatDecimalsOr(l.sd43910, 8, "-") << (l.slope_capped ? " (capped)" : "") << "</td><td>"
      << FormatDecimalsOr(l.sd43920_mm, 4, "-") << "</td><td>"
      << FormatDecimalsOr(l.error_max_abs_um, 2, "-") << " / "
      << FormatDecimalsOr(l.error_rms_um, 2, "-") << "</td><td>"
      << FormatDecimalsOr(l.uncorrected_max_abs_um, 2, "-") << " / "
      << FormatDecimalsOr(l.uncorrected_rms_um, 2, "-") << "</td></tr>\n";
  h << "</table>\n<p class='small'>sign " << interp::ToString(lines[0].options.sign)
    << " (dK = s &middot; line / 1000, interp/sinumerik.h); check it on the machine.</p>\n";
  return h.str();
}

std::string PointsHtml(const SurfaceFit& f) {
  std::ostringstream h;
  h << "<h2>Measured points</h2>\n<table><tr><th>#</th><th>x [mm]</th><th>y [mm]</th>"
       "<th>error [um]</th><th>fitted [um]</th><th>residual [um]</th><th>leave-one-out "
       "error [um]</th></tr>\n";
  for (std::size_t k = 0; k < f.points.size(); ++k)
    h << "<tr><td>" << k + 1 << "</td><td>" << FormatDecimalsOr(f.points[k].x_mm, 2, "-")
      << "</td><td>" << FormatDecimalsOr(f.points[k].y_mm, 2, "-") << "</td><td>"
      << FormatDecimalsOr(f.points[k].error_um, 3, "-") << "</td><td>"
      << FormatDecimalsOr(f.fitted_um[k], 3, "-") << "</td><td>"
      << FormatDecimalsOr(f.residual_um[k], 3, "-") << "</td><td>"
      << FormatDecimalsOr(f.loo_error_um[k], 3, "-") << "</td></tr>\n";
  h << "</table>\n";
  return h.str();
}

std::string PageHtml(const SurfaceFit& f, const MethodComparison* choice,
                     const std::vector<AxisLine>& lines, const SurfaceReportOptions& o,
                     bool have_map, const std::vector<std::string>& warnings) {
  std::ostringstream h;
  h << HtmlPageBegin(o.title, o.provenance);  // the shared skeleton (core/html_page.h)
  for (const auto& w : warnings) h << "<p><b>warning:</b> " << HtmlEscape(w) << "</p>\n";
  if (have_map)
    h << "<p><img src='map.png' alt='map of the thermal error over the table' width='1000'></p>\n";
  h << "<h2>Fit</h2>\n" << SummaryHtml(f);
  if (choice)
    h << "<h2>Cubic polynomial or B-spline</h2>\n<pre>" << HtmlEscape(FormatComparisonText(*choice))
      << "</pre>\n";
  h << LinesHtml(lines) << PointsHtml(f)
    << "<p class='small'>Files: surface_grid.dat, points.csv, points.dat, map.gp (re-plot with "
       "gnuplot "
       "map.gp).</p>\n</body></html>\n";
  return h.str();
}

}  // namespace

SurfaceReportResult WriteSurfaceReport(const fs::path& dir, const SurfaceFit& fit,
                                       const MethodComparison* choice,
                                       const std::vector<AxisLine>& lines,
                                       const SurfaceReportOptions& o) {
  if (o.map_samples < 2 || o.map_samples > 401)
    throw InputError("map samples " + std::to_string(o.map_samples) + " is outside 2..401");
  OutputDir out(dir, "report directory");
  SurfaceReportResult r;
  const Bounds& b = fit.surface.bounds;
  const std::string subtitle = ToString(fit.surface.method) + " surface, " +
                               std::to_string(fit.points.size()) + " measured points (black dots)";
  const bool flat = b.x_max_mm <= b.x_min_mm || b.y_max_mm <= b.y_min_mm;
  out.Add("surface_grid.dat", GridData(fit, o.map_samples));
  std::vector<std::string> comments;
  for (const auto& p : o.provenance) comments.push_back(" " + p);
  out.Add("points.csv", FormatPointsCsv(fit.points, comments));
  out.Add("points.dat", PointsData(fit));
  out.Add("map.gp", MapScript(o, Terminal(o.gnuplot_command), subtitle));
  if (o.plots && !flat) r.plot_rendered = Render(out, o, r);
  if (flat) r.warnings.push_back("the points span no rectangle: map skipped");
  out.Add("index.html", PageHtml(fit, choice, lines, o, r.plot_rendered, r.warnings));
  r.files = out.Commit(o.also_write);
  r.index_html = dir / "index.html";
  return r;
}

}  // namespace whirl::surface
