#pragma once
// Thermal error over the whole worktable (the worktable chapter, docs/references.md): the manual of
// src/product/surface.
//
// The method measures the thermal error at P points of the table, builds a model per point from its
// sensitive temperatures (surface/per_point.h; the models themselves come from src/product/drift through
// surface/drift_adapter.h), and at any moment turns the P predicted errors into a surface over
// the table, so the error is known at every position:
//   - a cubic polynomial in X and Y, 10 coefficients by least squares (surface/cubic.h), for a
//     smooth, low-order field (scattered points allowed);
//   - a tensor-product B-spline interpolating a rectangular M x N grid (surface/bspline.h), where
//     the field is too rough for a low-order fit (Runge oscillation at the edges); no
//     extrapolation.
// Choosing between them from the leave-one-out error (surface/choice.h), and the per-axis line a
// SINUMERIK 840D can apply, SD43900/SD43910/SD43920 (surface/line840d.h). Synthetic fields for
// tests and the demo: synthetic/surface.h. HTML page with a map: surface/report.h.
//
// Units everywhere: positions in mm (x_mm, y_mm), errors in um (error_um).
// Surface file (JSON, schema "whirl.surface", schema_version 1):
//   method "cubic" | "bspline"; bounds {x_min_mm, x_max_mm, y_min_mm, y_max_mm} of the points;
//   cubic: {terms (text), x_center_mm, y_center_mm, x_half_range_mm, y_half_range_mm, b_um (10,
//           in the normalized u, v), a_mm (10, the seed's form in mm), condition_number,
//           condition_number_mm};
//   bspline: {degree, grid_x_mm (N), grid_y_mm (M), knots_x_mm, knots_y_mm, weights_um (M rows
//           of N), condition_number};
//   points [{x_mm, y_mm, error_um, fitted_um, residual_um, loo_error_um (null: undefined)}];
//   summary {rms_residual_um, max_abs_residual_um, loo_rms_um, loo_max_abs_um, loo_count};
//   provenance [strings].
// Reading it back (SurfaceFromJson) checks the schema, the lengths, the knot rule and the range of
// every number (CheckSurface), the same checks a fit passes before it is written.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "surface/bspline.h"
#include "surface/cubic.h"
#include "surface/points.h"

namespace whirl::surface {

enum class Method { kCubic, kBspline };
std::string ToString(Method m);               ///< "cubic" / "bspline"
Method ParseMethod(const std::string& text);  ///< InputError for other strings

/// A fitted surface of either kind.
struct Surface {
  Method method = Method::kCubic;
  Bounds bounds;           ///< of the points it was fitted to
  CubicSurface cubic;      ///< when method == kCubic
  BsplineSurface bspline;  ///< when method == kBspline
  /// Error at (x, y), um. B-spline: InputError outside the grid. Cubic: defined everywhere;
  /// outside `bounds` it extrapolates (see Inside).
  double Evaluate(double x_mm, double y_mm) const;
  /// True when (x, y) is within the measured rectangle.
  bool Inside(double x_mm, double y_mm) const { return bounds.Contains(x_mm, y_mm); }
};

/// Largest |coefficient| of a surface, um: |b_um| of the cubic, |weights_um| of the B-spline
/// (1 km: far beyond any thermal error, so only a corrupt or hand-made file reaches it). With it,
/// positions within kMaxCoordinateMm and half ranges of at least kSamePositionMm, an evaluation
/// stays finite.
inline constexpr double kMaxSurfaceCoefficientUm = 1e12;

/// The ranges of a surface, as the file names them: bounds.* and the cubic's centre within
/// +-kMaxCoordinateMm mm, x_min_mm <= x_max_mm (and y), half ranges in [kSamePositionMm,
/// kMaxCoordinateMm] mm, grid lines within +-kMaxCoordinateMm mm, coefficients within
/// +-kMaxSurfaceCoefficientUm um. InputError "<what>: <field> = <value> breaks the rule: ...".
void CheckSurface(const Surface& surface, const std::string& what);

struct SurfaceFitOptions {
  Method method = Method::kCubic;
  /// B-spline degree p in X and Y, 1..kMaxDegree (3: bicubic). Ignored by the cubic.
  int degree = 3;
};

/// Per-point diagnostics and summary of a fit.
struct SurfaceFit {
  Surface surface;
  std::vector<SurfacePoint> points;
  std::vector<double> fitted_um;     ///< surface at each point
  std::vector<double> residual_um;   ///< measured - fitted
  std::vector<double> loo_error_um;  ///< measured - leave-one-out prediction; NaN: undefined
  double condition_number = 0;       ///< cubic: normalized design; B-spline: max of B_X, B_Y
  double condition_number_mm = 0;    ///< cubic only: raw design in mm
  std::vector<std::string> provenance;
};

/// Summary statistics of a per-point error vector (NaN entries skipped).
struct ErrorStats {
  std::size_t count = 0;  ///< defined entries
  double rms_um = NAN;    ///< NaN when count == 0
  double max_abs_um = NAN;
};
ErrorStats StatsOf(const std::vector<double>& errors_um);

/// Fits the chosen surface. InputError from cubic.h / bspline.h rules, and from CheckSurface, so a
/// written surface file always reads back.
SurfaceFit FitSurface(const std::vector<SurfacePoint>& points, const SurfaceFitOptions& options);

/// The surface file (schema above).
nlohmann::json SurfaceFitToJson(const SurfaceFit& fit);
/// Reads the surface part back; `what` names the file in messages.
Surface SurfaceFromJson(const nlohmann::json& j, const std::string& what);
Surface ReadSurfaceFile(const std::filesystem::path& path);

/// Prediction at query positions.
struct PredictedPoint {
  double x_mm = 0, y_mm = 0, error_um = 0;
  bool inside = true;  ///< false: cubic extrapolation outside the measured rectangle
};
/// B-spline: InputError naming the first query outside the grid (and its index).
std::vector<PredictedPoint> Predict(const Surface& surface,
                                    const std::vector<std::pair<double, double>>& xy);
nlohmann::json PredictionsToJson(const Surface& surface, const std::vector<PredictedPoint>& p);
/// CSV x_mm,y_mm,error_um of predictions with '#' comment lines (each through OneLine).
std::string FormatPredictionsCsv(const std::vector<PredictedPoint>& p,
                                 const std::vector<std::string>& comments);

/// Terminal text of a fit: method, coefficients or grid, condition, residual and LOO per point.
std::string FormatFitText(const SurfaceFit& fit);

}  // namespace whirl::surface
