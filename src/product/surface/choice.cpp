#include "surface/choice.h"

#include <algorithm>
#include <cmath>

#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"

namespace whirl::surface {
namespace {

using nlohmann::json;

// "1.234 um", or "-" when there is no value.
std::string Um(double x) { return std::isnan(x) ? "-" : FormatDecimals(x, 3) + " um"; }

json StatsJson(const ErrorStats& s) {
  auto n = [](double x) { return std::isnan(x) ? json(nullptr) : json(x); };
  return {{"count", s.count}, {"rms_um", n(s.rms_um)}, {"max_abs_um", n(s.max_abs_um)}};
}

std::vector<double> Masked(const std::vector<double>& v, const std::vector<bool>& keep) {
  std::vector<double> out;
  for (std::size_t k = 0; k < v.size(); ++k) out.push_back(keep[k] ? v[k] : NAN);
  return out;
}

bool OnEdge(const SurfacePoint& p, const Bounds& b) {
  auto near = [](double a, double c) { return std::abs(a - c) <= kSamePositionMm; };
  return near(p.x_mm, b.x_min_mm) || near(p.x_mm, b.x_max_mm) || near(p.y_mm, b.y_min_mm) ||
         near(p.y_mm, b.y_max_mm);
}

double Overshoot(const CubicSurface& c, const Bounds& b, double lo, double hi, int n) {
  double worst = 0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = b.x_min_mm + (b.x_max_mm - b.x_min_mm) * j / (n - 1);
      const double y = b.y_min_mm + (b.y_max_mm - b.y_min_mm) * i / (n - 1);
      const double e = c.Evaluate(x, y);
      worst = std::max({worst, e - hi, lo - e});
    }
  return worst;
}

void AnalyzeCubic(MethodComparison& c, const std::vector<SurfacePoint>& points) {
  const CubicFit fit = FitCubic(points);
  c.cubic_available = true;
  c.cubic_loo_um = fit.loo_error_um;
  c.cubic_loo = StatsOf(fit.loo_error_um);
  const Bounds b = BoundsOf(points);
  std::vector<bool> edge;
  for (const auto& p : points) edge.push_back(OnEdge(p, b));
  std::vector<bool> interior(edge.size());
  std::transform(edge.begin(), edge.end(), interior.begin(), [](bool e) { return !e; });
  c.cubic_loo_edge = StatsOf(Masked(fit.loo_error_um, edge));
  c.cubic_loo_interior = StatsOf(Masked(fit.loo_error_um, interior));
  double lo = points[0].error_um, hi = lo;
  for (const auto& p : points) lo = std::min(lo, p.error_um), hi = std::max(hi, p.error_um);
  c.measured_range_um = hi - lo;
  c.cubic_overshoot_um = Overshoot(fit.surface, b, lo, hi, c.options.map_samples);
  const double excess = c.options.min_excess_um;
  const bool edge_worse =
      c.cubic_loo_edge.count && c.cubic_loo_interior.count &&
      c.cubic_loo_edge.rms_um > c.options.edge_ratio * c.cubic_loo_interior.rms_um &&
      c.cubic_loo_edge.rms_um - c.cubic_loo_interior.rms_um > excess;
  const bool overshoots =
      c.cubic_overshoot_um > c.options.overshoot_fraction * c.measured_range_um &&
      c.cubic_overshoot_um > excess;
  c.cubic_oscillates = edge_worse || overshoots;
  if (edge_worse)
    c.note = "edge LOO RMS " + Um(c.cubic_loo_edge.rms_um) + " > " +
             FormatNumber(c.options.edge_ratio) + " x interior " + Um(c.cubic_loo_interior.rms_um);
  if (overshoots)
    c.note += std::string(c.note.empty() ? "" : "; ") + "it leaves the measured range by " +
              Um(c.cubic_overshoot_um) + " (> " + FormatNumber(c.options.overshoot_fraction) +
              " x range " + Um(c.measured_range_um) + ")";
  if (c.cubic_oscillates)
    c.note = "the cubic polynomial oscillates at the edges (Runge): " + c.note +
             "; a low-order fit does not describe this field, prefer the B-spline on a grid";
}

void Recommend(MethodComparison& c) {
  if (!c.bspline_available) {
    c.recommended = Method::kCubic;
    c.reason = "only the cubic can run (B-spline: " + c.bspline_refusal + ")";
    return;
  }
  if (!c.cubic_available) {
    c.recommended = Method::kBspline;
    c.reason = "only the B-spline can run (cubic: " + c.cubic_refusal + ")";
    return;
  }
  std::vector<bool> common;
  for (std::size_t k = 0; k < c.cubic_loo_um.size(); ++k)
    common.push_back(!std::isnan(c.cubic_loo_um[k]) && !std::isnan(c.bspline_loo_um[k]));
  c.cubic_loo_common = StatsOf(Masked(c.cubic_loo_um, common));
  c.bspline_loo_common = StatsOf(Masked(c.bspline_loo_um, common));
  if (c.cubic_loo_common.count == 0) {
    c.recommended = Method::kCubic;
    c.reason = "no point has a leave-one-out error under both methods; the cubic is the simpler";
    return;
  }
  // A tie (within 1e-6 um, e.g. both exact on a cubic field) goes to the simpler cubic.
  const bool spline_better = c.bspline_loo_common.rms_um < c.cubic_loo_common.rms_um - 1e-6;
  c.recommended = spline_better ? Method::kBspline : Method::kCubic;
  c.reason = std::string(spline_better ? "bspline" : "cubic") +
             ": lower leave-one-out RMS on the " + std::to_string(c.cubic_loo_common.count) +
             " common points (cubic " + Um(c.cubic_loo_common.rms_um) + ", B-spline " +
             Um(c.bspline_loo_common.rms_um) + ")";
}

}  // namespace

void ChoiceOptions::Validate() const {
  if (degree < 1 || degree > kMaxDegree)
    throw InputError("degree " + std::to_string(degree) + " is outside 1.." +
                     std::to_string(kMaxDegree));
  if (!(edge_ratio > 1))
    throw InputError("edge_ratio " + FormatNumber(edge_ratio) + " must be > 1");
  if (!(overshoot_fraction > 0))
    throw InputError("overshoot_fraction " + FormatNumber(overshoot_fraction) + " must be > 0");
  if (!(min_excess_um >= 0))
    throw InputError("min_excess_um " + FormatNumber(min_excess_um) + " must be >= 0");
  if (map_samples < 2 || map_samples > 1001)
    throw InputError("map_samples " + std::to_string(map_samples) + " is outside 2..1001");
}

MethodComparison CompareMethods(const std::vector<SurfacePoint>& points,
                                const ChoiceOptions& options) {
  options.Validate();
  MethodComparison c;
  c.options = options;
  try {
    AnalyzeCubic(c, points);
  } catch (const InputError& e) {
    c.cubic_refusal = e.what();
  }
  try {
    const BsplineFit b = FitBsplinePoints(points, options.degree);
    c.bspline_available = true;
    c.bspline_loo_um = b.loo_error_um;
    c.bspline_loo = StatsOf(b.loo_error_um);
  } catch (const InputError& e) {
    c.bspline_refusal = e.what();
  }
  if (!c.cubic_available && !c.bspline_available)
    throw InputError("neither surface can be fitted: cubic: " + c.cubic_refusal +
                     "; B-spline: " + c.bspline_refusal);
  Recommend(c);
  return c;
}

nlohmann::json ComparisonToJson(const MethodComparison& c) {
  auto loo = [](const std::vector<double>& v) {
    json a = json::array();
    for (double x : v) a.push_back(std::isnan(x) ? json(nullptr) : json(x));
    return a;
  };
  json j = {{"schema", "whirl.surface_choice"},
            {"schema_version", 1},
            {"degree", c.options.degree},
            {"recommended", ToString(c.recommended)},
            {"reason", c.reason},
            {"cubic_oscillates", c.cubic_oscillates},
            {"note", c.note},
            {"measured_range_um", c.measured_range_um}};
  j["cubic"] = {
      {"available", c.cubic_available},          {"refusal", c.cubic_refusal},
      {"loo", StatsJson(c.cubic_loo)},           {"loo_common", StatsJson(c.cubic_loo_common)},
      {"loo_edge", StatsJson(c.cubic_loo_edge)}, {"loo_interior", StatsJson(c.cubic_loo_interior)},
      {"overshoot_um", c.cubic_overshoot_um},    {"loo_error_um", loo(c.cubic_loo_um)}};
  j["bspline"] = {{"available", c.bspline_available},
                  {"refusal", c.bspline_refusal},
                  {"loo", StatsJson(c.bspline_loo)},
                  {"loo_common", StatsJson(c.bspline_loo_common)},
                  {"loo_error_um", loo(c.bspline_loo_um)}};
  return j;
}

std::string FormatComparisonText(const MethodComparison& c) {
  std::string s = "leave-one-out error (measured - prediction without the point):\n";
  auto line = [&](const char* name, bool ok, const std::string& refusal, const ErrorStats& all,
                  const ErrorStats& common) {
    s += std::string("  ") + name + ": ";
    if (!ok) {
      s += "not available (" + refusal + ")\n";
      return;
    }
    s += "RMS " + Um(all.rms_um) + ", max " + Um(all.max_abs_um) + " over " +
         std::to_string(all.count) + " points; on the common points RMS " + Um(common.rms_um) +
         ", max " + Um(common.max_abs_um) + "\n";
  };
  line("cubic   ", c.cubic_available, c.cubic_refusal, c.cubic_loo, c.cubic_loo_common);
  line("B-spline", c.bspline_available, c.bspline_refusal, c.bspline_loo, c.bspline_loo_common);
  if (c.cubic_available)
    s += "  cubic LOO RMS at the edges " + Um(c.cubic_loo_edge.rms_um) + ", inside " +
         Um(c.cubic_loo_interior.rms_um) + "; overshoot beyond the measured range " +
         Um(c.cubic_overshoot_um) + "\n";
  s += "recommended: " + c.reason + "\n";
  if (!c.note.empty()) s += "note: " + c.note + "\n";
  return s;
}

}  // namespace whirl::surface
