#include "surface/surface.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/numbers.h"

namespace whirl::surface {
namespace {

using nlohmann::json;

json NullIfNan(double x) { return std::isnan(x) ? json(nullptr) : json(x); }

json BoundsJson(const Bounds& b) {
  return {{"x_min_mm", b.x_min_mm},
          {"x_max_mm", b.x_max_mm},
          {"y_min_mm", b.y_min_mm},
          {"y_max_mm", b.y_max_mm}};
}

std::vector<double> Numbers(const json& j, const char* key, const std::string& what) {
  return RequireNumbers(RequireKey(j, key, what), what + ": '" + key + "'");
}

json CubicJson(const SurfaceFit& f) {
  const CubicSurface& c = f.surface.cubic;
  return {{"terms",
           "a0 + a1 X + a2 Y + a3 X^2 + a4 X Y + a5 Y^2 + a6 X^3 + a7 X^2 Y + "
           "a8 X Y^2 + a9 Y^3 (b: the same terms in u = (X - x_center) / x_half_range, "
           "v = (Y - y_center) / y_half_range)"},
          {"x_center_mm", c.x_center_mm},
          {"y_center_mm", c.y_center_mm},
          {"x_half_range_mm", c.x_half_range_mm},
          {"y_half_range_mm", c.y_half_range_mm},
          {"b_um", c.b},
          {"a_mm", c.CoefficientsMm()},
          {"condition_number", f.condition_number},
          {"condition_number_mm", f.condition_number_mm}};
}

json BsplineJson(const SurfaceFit& f) {
  const BsplineSurface& s = f.surface.bspline;
  json w = json::array();
  for (Eigen::Index i = 0; i < s.weights.rows(); ++i) {
    std::vector<double> row;
    for (Eigen::Index j = 0; j < s.weights.cols(); ++j) row.push_back(s.weights(i, j));
    w.push_back(row);
  }
  return {{"degree", s.degree},
          {"grid_x_mm", s.grid_x},
          {"grid_y_mm", s.grid_y},
          {"knots_x_mm", s.knots_x},
          {"knots_y_mm", s.knots_y},
          {"weights_um", w},
          {"condition_number", f.condition_number}};
}

CubicSurface CubicFromJson(const json& j, const std::string& what) {
  CubicSurface c;
  c.x_center_mm = RequireNumber(j, "x_center_mm", what);
  c.y_center_mm = RequireNumber(j, "y_center_mm", what);
  c.x_half_range_mm = RequireNumber(j, "x_half_range_mm", what);
  c.y_half_range_mm = RequireNumber(j, "y_half_range_mm", what);
  const std::vector<double> b = Numbers(j, "b_um", what);
  if (b.size() != kCubicTerms) throw InputError(what + ": 'b_um' must hold 10 coefficients");
  for (int k = 0; k < kCubicTerms; ++k) c.b[k] = b[k];
  return c;
}

BsplineSurface BsplineFromJson(const json& j, const std::string& what) {
  BsplineSurface s;
  const double degree = RequireNumber(j, "degree", what);
  s.degree = static_cast<int>(degree);
  if (s.degree != degree || s.degree < 1 || s.degree > kMaxDegree)
    throw InputError(what + ": 'degree' must be an integer in 1.." + std::to_string(kMaxDegree));
  s.grid_x = Numbers(j, "grid_x_mm", what);
  s.grid_y = Numbers(j, "grid_y_mm", what);
  s.knots_x = Numbers(j, "knots_x_mm", what);
  s.knots_y = Numbers(j, "knots_y_mm", what);
  for (const auto* g : {&s.grid_x, &s.grid_y})
    if (g->size() < static_cast<std::size_t>(s.degree) + 1 || g->size() > kMaxGridLines)
      throw InputError(what + ": a grid needs degree + 1 to " + std::to_string(kMaxGridLines) +
                       " lines");
  // The knots must be the stated construction of the grid (not any vector of the right length).
  if (ClampedAveragedKnots(s.grid_x, s.degree) != s.knots_x ||
      ClampedAveragedKnots(s.grid_y, s.degree) != s.knots_y)
    throw InputError(what +
                     ": knots_x_mm/knots_y_mm are not the clamped averaged knots of the "
                     "grid (surface/bspline.h)");
  const json& w = RequireKey(j, "weights_um", what);
  if (!w.is_array() || w.size() != s.grid_y.size())
    throw InputError(what + ": 'weights_um' must hold one row per grid_y line");
  s.weights.resize(static_cast<Eigen::Index>(s.grid_y.size()),
                   static_cast<Eigen::Index>(s.grid_x.size()));
  for (std::size_t i = 0; i < w.size(); ++i) {
    const std::vector<double> row =
        RequireNumbers(w[i], what + ": 'weights_um[" + std::to_string(i) + "]'");
    if (row.size() != s.grid_x.size())
      throw InputError(what + ": weights_um row " + std::to_string(i + 1) +
                       " must hold one value per grid_x line");
    for (std::size_t k = 0; k < row.size(); ++k)
      s.weights(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)) = row[k];
  }
  return s;
}

const Range kCoordinate{-kMaxCoordinateMm, kMaxCoordinateMm, false, "mm"};
const Range kHalfRange{kSamePositionMm, kMaxCoordinateMm, false, "mm"};
const Range kCoefficient{-kMaxSurfaceCoefficientUm, kMaxSurfaceCoefficientUm, false, "um"};

std::string Indexed(const char* name, std::size_t i) {
  return name + ("[" + std::to_string(i) + "]");
}

void CheckBounds(const Bounds& b, const std::string& what) {
  CheckRange(b.x_min_mm, kCoordinate, "bounds.x_min_mm", what);
  CheckRange(b.x_max_mm, kCoordinate, "bounds.x_max_mm", what);
  CheckRange(b.y_min_mm, kCoordinate, "bounds.y_min_mm", what);
  CheckRange(b.y_max_mm, kCoordinate, "bounds.y_max_mm", what);
  if (b.x_min_mm > b.x_max_mm || b.y_min_mm > b.y_max_mm)
    throw InputError(what + ": bounds: x_min_mm must not exceed x_max_mm, nor y_min_mm y_max_mm");
}

}  // namespace

std::string ToString(Method m) { return m == Method::kCubic ? "cubic" : "bspline"; }

Method ParseMethod(const std::string& text) {
  if (text == "cubic") return Method::kCubic;
  if (text == "bspline") return Method::kBspline;
  throw InputError("surface method '" + text + "' is not 'cubic' or 'bspline'");
}

void CheckSurface(const Surface& s, const std::string& what) {
  CheckBounds(s.bounds, what);
  if (s.method == Method::kCubic) {
    const CubicSurface& c = s.cubic;
    CheckRange(c.x_center_mm, kCoordinate, "cubic.x_center_mm", what);
    CheckRange(c.y_center_mm, kCoordinate, "cubic.y_center_mm", what);
    CheckRange(c.x_half_range_mm, kHalfRange, "cubic.x_half_range_mm", what);
    CheckRange(c.y_half_range_mm, kHalfRange, "cubic.y_half_range_mm", what);
    for (std::size_t k = 0; k < c.b.size(); ++k)
      CheckRange(c.b[k], kCoefficient, Indexed("cubic.b_um", k), what);
    return;
  }
  const BsplineSurface& b = s.bspline;
  for (std::size_t i = 0; i < b.grid_x.size(); ++i)
    CheckRange(b.grid_x[i], kCoordinate, Indexed("bspline.grid_x_mm", i), what);
  for (std::size_t i = 0; i < b.grid_y.size(); ++i)
    CheckRange(b.grid_y[i], kCoordinate, Indexed("bspline.grid_y_mm", i), what);
  for (Eigen::Index i = 0; i < b.weights.rows(); ++i)
    for (Eigen::Index k = 0; k < b.weights.cols(); ++k)
      CheckRange(b.weights(i, k), kCoefficient,
                 Indexed("bspline.weights_um", static_cast<std::size_t>(i)) + "[" +
                     std::to_string(k) + "]",
                 what);
}

double Surface::Evaluate(double x_mm, double y_mm) const {
  return method == Method::kCubic ? cubic.Evaluate(x_mm, y_mm) : bspline.Evaluate(x_mm, y_mm);
}

ErrorStats StatsOf(const std::vector<double>& e) {
  ErrorStats s;
  double sum2 = 0, max_abs = 0;
  for (double x : e)
    if (!std::isnan(x)) ++s.count, sum2 += x * x, max_abs = std::max(max_abs, std::abs(x));
  if (s.count) s.rms_um = std::sqrt(sum2 / static_cast<double>(s.count)), s.max_abs_um = max_abs;
  return s;
}

SurfaceFit FitSurface(const std::vector<SurfacePoint>& points, const SurfaceFitOptions& options) {
  SurfaceFit f;
  f.points = points;
  f.surface.method = options.method;
  f.surface.bounds = BoundsOf(points);
  if (options.method == Method::kCubic) {
    CubicFit c = FitCubic(points);
    f.surface.cubic = c.surface;
    f.residual_um = c.residual_um;
    f.loo_error_um = c.loo_error_um;
    f.condition_number = c.condition_number;
    f.condition_number_mm = c.condition_number_mm;
  } else {
    BsplineFit b = FitBsplinePoints(points, options.degree);
    f.surface.bspline = b.surface;
    f.residual_um = b.residual_um;
    f.loo_error_um = b.loo_error_um;
    f.condition_number = std::max(b.condition_x, b.condition_y);
    f.condition_number_mm = NAN;
  }
  for (std::size_t k = 0; k < points.size(); ++k)
    f.fitted_um.push_back(points[k].error_um - f.residual_um[k]);
  CheckSurface(f.surface, "surface fit");  // what is written reads back
  return f;
}

nlohmann::json SurfaceFitToJson(const SurfaceFit& f) {
  json pts = json::array();
  for (std::size_t k = 0; k < f.points.size(); ++k)
    pts.push_back({{"x_mm", f.points[k].x_mm},
                   {"y_mm", f.points[k].y_mm},
                   {"error_um", f.points[k].error_um},
                   {"fitted_um", f.fitted_um[k]},
                   {"residual_um", f.residual_um[k]},
                   {"loo_error_um", NullIfNan(f.loo_error_um[k])}});
  const ErrorStats res = StatsOf(f.residual_um), loo = StatsOf(f.loo_error_um);
  json j = {{"schema", "whirl.surface"},
            {"schema_version", 1},
            {"method", ToString(f.surface.method)},
            {"bounds", BoundsJson(f.surface.bounds)},
            {"points", pts},
            {"summary",
             {{"point_count", f.points.size()},
              {"rms_residual_um", res.rms_um},
              {"max_abs_residual_um", res.max_abs_um},
              {"loo_rms_um", NullIfNan(loo.rms_um)},
              {"loo_max_abs_um", NullIfNan(loo.max_abs_um)},
              {"loo_count", loo.count}}},
            {"provenance", f.provenance}};
  if (f.surface.method == Method::kCubic)
    j["cubic"] = CubicJson(f);
  else
    j["bspline"] = BsplineJson(f);
  return j;
}

Surface SurfaceFromJson(const nlohmann::json& j, const std::string& what) {
  if (!j.is_object() || !j.contains("schema") || j.at("schema") != "whirl.surface")
    throw InputError(what + ": not a whirl surface file (schema 'whirl.surface' expected)");
  RequireSchema(j, "whirl.surface", 1, what);
  Surface s;
  s.method = ParseMethod(RequireOneOf(j, "method", {"cubic", "bspline"}, what));
  if (!j.contains("bounds")) throw InputError(what + ": missing 'bounds'");
  const json& b = j.at("bounds");
  s.bounds = {RequireNumber(b, "x_min_mm", what), RequireNumber(b, "x_max_mm", what),
              RequireNumber(b, "y_min_mm", what), RequireNumber(b, "y_max_mm", what)};
  const char* key = s.method == Method::kCubic ? "cubic" : "bspline";
  if (!j.contains(key))
    throw InputError(what + ": method '" + ToString(s.method) + "' but no '" + key + "' object");
  if (s.method == Method::kCubic)
    s.cubic = CubicFromJson(j.at(key), what);
  else
    s.bspline = BsplineFromJson(j.at(key), what);
  CheckSurface(s, what);
  return s;
}

Surface ReadSurfaceFile(const std::filesystem::path& path) {
  try {
    return SurfaceFromJson(ReadJsonFile(path), "surface file '" + path.string() + "'");
  } catch (const nlohmann::json::exception& e) {
    throw InputError("surface file '" + path.string() + "': " + e.what());
  }
}

std::vector<PredictedPoint> Predict(const Surface& surface,
                                    const std::vector<std::pair<double, double>>& xy) {
  std::vector<PredictedPoint> out;
  for (std::size_t k = 0; k < xy.size(); ++k) {
    const auto [x, y] = xy[k];
    CheckPosition(x, y, "query " + std::to_string(k + 1));
    try {
      out.push_back({x, y, surface.Evaluate(x, y), surface.Inside(x, y)});
    } catch (const InputError& e) {
      throw InputError("query " + std::to_string(k + 1) + ": " + e.what());
    }
  }
  return out;
}

nlohmann::json PredictionsToJson(const Surface& surface, const std::vector<PredictedPoint>& p) {
  json rows = json::array();
  std::size_t outside = 0;
  for (const auto& q : p) {
    rows.push_back({{"x_mm", q.x_mm},
                    {"y_mm", q.y_mm},
                    {"error_um", q.error_um},
                    {"inside_measured_rectangle", q.inside}});
    outside += q.inside ? 0 : 1;
  }
  return {{"schema", "whirl.surface_prediction"}, {"schema_version", 1},
          {"method", ToString(surface.method)},   {"bounds", BoundsJson(surface.bounds)},
          {"extrapolated_count", outside},        {"predictions", rows}};
}

std::string FormatPredictionsCsv(const std::vector<PredictedPoint>& p,
                                 const std::vector<std::string>& comments) {
  std::vector<SurfacePoint> points;
  for (const auto& q : p) points.push_back({q.x_mm, q.y_mm, q.error_um});
  return FormatPointsCsv(points, comments);
}

std::string FormatFitText(const SurfaceFit& f) {
  std::ostringstream s;
  const Bounds& b = f.surface.bounds;
  s << "surface: " << ToString(f.surface.method) << " over " << f.points.size() << " points, x "
    << FormatDecimalsOr(b.x_min_mm, 1, "-") << ".." << FormatDecimalsOr(b.x_max_mm, 1, "-")
    << " mm, y " << FormatDecimalsOr(b.y_min_mm, 1, "-") << ".."
    << FormatDecimalsOr(b.y_max_mm, 1, "-") << " mm\n";
  if (f.surface.method == Method::kCubic) {
    const auto a = f.surface.cubic.CoefficientsMm();
    s << "  dE = a0 + a1 X + a2 Y + a3 X^2 + a4 XY + a5 Y^2 + a6 X^3 + a7 X^2Y + a8 XY^2 + a9 Y^3"
         " (um, X/Y in mm)\n";
    for (int k = 0; k < kCubicTerms; ++k)
      s << "  a" << k << " = " << FormatExponent(a[k], 6) << "\n";
    s << "  condition number " << FormatDecimals(f.condition_number, 1) << " (normalized u, v), "
      << FormatSignificant(f.condition_number_mm, 3) << " (raw mm)\n";
  } else {
    const BsplineSurface& bs = f.surface.bspline;
    s << "  degree " << bs.degree << ", grid " << bs.grid_y.size() << " rows x " << bs.grid_x.size()
      << " columns, condition number of the collocation matrices "
      << FormatDecimalsOr(f.condition_number, 1, "-") << "\n";
  }
  s << "  point        x_mm        y_mm    error_um   fitted_um  residual_um  loo_error_um\n";
  for (std::size_t k = 0; k < f.points.size(); ++k) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "  %5zu %11.2f %11.2f %11.3f %11.3f %12.3f %13s\n", k + 1,
                  f.points[k].x_mm, f.points[k].y_mm, f.points[k].error_um, f.fitted_um[k],
                  f.residual_um[k], FormatDecimalsOr(f.loo_error_um[k], 3, "-").c_str());
    s << buf;
  }
  const ErrorStats res = StatsOf(f.residual_um), loo = StatsOf(f.loo_error_um);
  s << "  residual: RMS " << FormatDecimalsOr(res.rms_um, 3, "-") << " um, max |.| "
    << FormatDecimalsOr(res.max_abs_um, 3, "-") << " um\n  leave-one-out: RMS "
    << FormatDecimalsOr(loo.rms_um, 3, "-") << " um, max |.| "
    << FormatDecimalsOr(loo.max_abs_um, 3, "-") << " um over " << loo.count << " of "
    << f.points.size() << " points\n";
  return s.str();
}

}  // namespace whirl::surface
