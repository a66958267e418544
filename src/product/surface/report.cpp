#include "surface/report.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/report_render.h"

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

using report::Cell;
using report::Col;
using report::SeriesKind;

// The map: the surface as colours with contour lines, the measured points on top. The picture
// takes the table's shape (`b`: one mm as long on X as on Y), so the map fills it: gnuplot keeps
// about 320 px beside the map (Y labels, the colour box) and 180 px above and below it.
report::Figure MapFigure(const SurfaceReportOptions& o, const std::string& subtitle,
                         const Bounds& b) {
  report::Panel p;
  p.title = o.title + ": " + subtitle;
  p.xlabel = "X [mm]";
  p.ylabel = "Y [mm]";
  p.cblabel = "thermal error [um]";
  p.equal_axes = true;
  p.series.push_back({"surface_grid.dat", -1, {Col(1), Col(2), Col(3)}, SeriesKind::kMap, "", "",
                      1.5, false, ""});
  p.series.push_back({"surface_grid.dat", -1, {Col(1), Col(2), Col(3)}, SeriesKind::kContour, "",
                      "#202020", 1, false, "contour lines of the surface"});
  p.series.push_back({"points.dat", -1, {Col(1), Col(2), Col(3)}, SeriesKind::kPoints, "",
                      "#000000", 1.5, false, "measured points"});
  report::Figure f;
  f.stem = "map";
  f.alt = "map of the thermal error over the table";
  const double dx = b.x_max_mm - b.x_min_mm, dy = b.y_max_mm - b.y_min_mm;
  const double aspect = dx > 0 && dy > 0 ? dy / dx : 1.0;  // height / width of the map
  constexpr double kBeside = 320, kAbove = 180, kMapWidth = 680, kMaxMapHeight = 720;
  const double map_height = std::min(kMaxMapHeight, kMapWidth * aspect);
  f.width_px = static_cast<int>(std::lround(kBeside + map_height / aspect));
  f.height_px = static_cast<int>(std::lround(kAbove + std::max(200.0, map_height)));
  f.panels = {p};
  return f;
}

report::Table SummaryTable(const SurfaceFit& f) {
  const ErrorStats res = StatsOf(f.residual_um), loo = StatsOf(f.loo_error_um);
  report::Table t;
  std::string method = ToString(f.surface.method);
  if (f.surface.method == Method::kBspline)
    method += ", degree " + std::to_string(f.surface.bspline.degree);
  std::string condition = FormatDecimalsOr(f.condition_number, 1, "-");
  if (f.surface.method == Method::kCubic)
    condition += " (normalized coordinates; " + FormatSignificant(f.condition_number_mm, 3) +
                 " in raw mm)";
  const auto left = [](std::string text) {
    Cell c(std::move(text));
    c.left = true;
    return c;
  };
  t.rows = {{"method", left(method)},
            {"points", left(std::to_string(f.points.size()))},
            {"condition number", left(condition)},
            {"residual RMS / max", left(FormatDecimalsOr(res.rms_um, 3, "-") + " / " +
                                        FormatDecimalsOr(res.max_abs_um, 3, "-") + " um")},
            {"leave-one-out RMS / max",
             left(FormatDecimalsOr(loo.rms_um, 3, "-") + " / " +
                  FormatDecimalsOr(loo.max_abs_um, 3, "-") + " um over " +
                  std::to_string(loo.count) + " points")}};
  return t;
}

void AddCubic(const SurfaceFit& f, report::Document* doc) {
  if (f.surface.method != Method::kCubic) return;
  const auto a = f.surface.cubic.CoefficientsMm();
  doc->Say("dE = a0 + a1 X + a2 Y + a3 X\u00b2 + a4 XY + a5 Y\u00b2 + a6 X\u00b3 + a7 X\u00b2Y + "
           "a8 XY\u00b2 + a9 Y\u00b3 (um, X and Y in mm)");
  report::Table t;
  t.rows.emplace_back();
  for (int k = 0; k < kCubicTerms; ++k) {
    t.header.push_back("a" + std::to_string(k));
    t.rows.back().push_back(FormatExponent(a[k], 4));
  }
  doc->Add(t);
}

void AddLines(const std::vector<AxisLine>& lines, report::Document* doc) {
  if (lines.empty()) return;
  doc->Add(report::Heading{
      2, "840D: the least-squares line per axis (what temperature compensation can apply)", ""});
  report::Table t;
  t.header = {"axis", "along", "SD43900 [mm]", "SD43910", "SD43920 [mm]", "error max / RMS [um]",
              "left by the line max / RMS [um]"};
  for (const auto& l : lines)
    t.rows.push_back({l.options.axis, std::string(1, l.options.along),
                      FormatDecimalsOr(l.sd43900_mm, 6, "-"),
                      FormatDecimalsOr(l.sd43910, 8, "-") + (l.slope_capped ? " (capped)" : ""),
                      FormatDecimalsOr(l.sd43920_mm, 4, "-"),
                      FormatDecimalsOr(l.error_max_abs_um, 2, "-") + " / " +
                          FormatDecimalsOr(l.error_rms_um, 2, "-"),
                      FormatDecimalsOr(l.uncorrected_max_abs_um, 2, "-") + " / " +
                          FormatDecimalsOr(l.uncorrected_rms_um, 2, "-")});
  t.caption = "sign " + interp::ToString(lines[0].options.sign) +
              " (dK = s \u00b7 line / 1000, interp/sinumerik.h); check it on the machine.";
  doc->Add(t);
}

// The cubic / B-spline comparison (choice.h) as a table: each method's leave-one-out error over
// its points and over the points both define, the cubic's edge / inside split and overshoot; the
// recommended method's row in bold, the reason and the oscillation note below.
report::Table ComparisonTable(const MethodComparison& c) {
  report::Table t;
  t.header = {"method", "points", "LOO RMS [um]", "LOO max [um]", "common points: RMS [um]",
              "common points: max [um]", "edges / inside: RMS [um]", "overshoot [um]"};
  const auto um = [](double x) { return FormatDecimalsOr(x, 3, "-"); };
  const auto row = [&](Method m, bool ok, const std::string& refusal, const ErrorStats& all,
                       const ErrorStats& common) {
    if (ok && m == c.recommended) t.highlight.push_back(t.rows.size());
    if (!ok) {
      report::Cell why("not available (" + refusal + ")");
      why.colspan = 7;
      why.left = true;
      t.rows.push_back({ToString(m), why});
      return;
    }
    const bool cubic = m == Method::kCubic;
    t.rows.push_back({ToString(m), std::to_string(all.count), um(all.rms_um), um(all.max_abs_um),
                      um(common.rms_um), um(common.max_abs_um),
                      cubic ? um(c.cubic_loo_edge.rms_um) + " / " + um(c.cubic_loo_interior.rms_um)
                            : "-",
                      cubic ? um(c.cubic_overshoot_um) : "-"});
  };
  row(Method::kCubic, c.cubic_available, c.cubic_refusal, c.cubic_loo, c.cubic_loo_common);
  row(Method::kBspline, c.bspline_available, c.bspline_refusal, c.bspline_loo,
      c.bspline_loo_common);
  t.caption = "Leave-one-out (LOO) error: measured - prediction without the point (the B-spline "
              "leaves out its row or column); common points: where both are defined; overshoot: "
              "how far the cubic leaves the measured range over the box. Recommended: " +
              c.reason + (c.note.empty() ? std::string() : "; note: " + c.note) + ".";
  return t;
}

report::Table PointsTable(const SurfaceFit& f) {
  report::Table t;
  t.header = {"#", "x [mm]", "y [mm]", "error [um]", "fitted [um]", "residual [um]",
              "leave-one-out error [um]"};
  for (std::size_t k = 0; k < f.points.size(); ++k)
    t.rows.push_back({std::to_string(k + 1), FormatDecimalsOr(f.points[k].x_mm, 2, "-"),
                      FormatDecimalsOr(f.points[k].y_mm, 2, "-"),
                      FormatDecimalsOr(f.points[k].error_um, 3, "-"),
                      FormatDecimalsOr(f.fitted_um[k], 3, "-"),
                      FormatDecimalsOr(f.residual_um[k], 3, "-"),
                      FormatDecimalsOr(f.loo_error_um[k], 3, "-")});
  return t;
}

report::Document Page(const SurfaceFit& f, const MethodComparison* choice,
                      const std::vector<AxisLine>& lines, const SurfaceReportOptions& o,
                      bool map, const std::string& subtitle) {
  report::Document doc;
  doc.title = o.title;
  doc.provenance = o.provenance;
  if (map) doc.Add(MapFigure(o, subtitle, f.surface.bounds));
  doc.Add(report::Heading{2, "Fit", ""}).Add(SummaryTable(f));
  AddCubic(f, &doc);
  if (choice) {
    doc.Add(report::Heading{2, "Cubic polynomial or B-spline", ""});
    doc.Add(ComparisonTable(*choice));
  }
  AddLines(lines, &doc);
  doc.Add(report::Heading{2, "Measured points", ""}).Add(PointsTable(f));
  doc.Say("Files: surface_grid.dat, points.csv, points.dat, map.gp (re-plot with gnuplot map.gp).",
          report::Tone::kSmall);
  return doc;
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
  std::vector<std::string> warnings;
  if (flat) warnings.push_back("the points span no rectangle: map skipped");
  report::RenderOptions ro;
  ro.plots = o.plots;
  ro.gnuplot = o.gnuplot_command;
  const report::RenderResult rendered =
      report::RenderReport(Page(fit, choice, lines, o, !flat, subtitle), out, ro, warnings);
  r.plot_rendered = rendered.plots_rendered;
  r.warnings = warnings;
  r.warnings.insert(r.warnings.end(), rendered.warnings.begin(), rendered.warnings.end());
  r.files = out.Commit(o.also_write);
  r.index_html = dir / "index.html";
  return r;
}

}  // namespace whirl::surface
