#pragma once
// Cubic polynomial surface fitted by least squares (the worktable chapter's "multiple
// regression surface fit").
//
// The model, 10 coefficients, this order of terms (the seed's formula did not survive in the text;
// this is the project's order, used everywhere: JSON, --help, tests):
//
//   dE(X, Y) = a0 + a1 X + a2 Y + a3 X^2 + a4 X Y + a5 Y^2
//                 + a6 X^3 + a7 X^2 Y + a8 X Y^2 + a9 Y^3           X, Y in mm, dE in um
//
// Solved in normalized coordinates so the least-squares problem is well conditioned:
//   u = (X - xc) / hx,  v = (Y - yc) / hy,  xc, yc = centre and hx, hy = half width of the bounding
//   box of the points (u, v in [-1, 1]); b0..b9 are the coefficients of the same 10 terms in u, v.
// a0..a9 (per mm^k) follow from b0..b9 by exact binomial expansion (CubicSurface::CoefficientsMm).
//
// Solver: column-pivoting Householder QR (Eigen ColPivHouseholderQR) of the P x 10 design matrix.
// Refused (InputError): fewer than 10 distinct positions; or a design of rank < 10 (the points lie
//   on one cubic curve, e.g. all on a few lines), named with its rank.
// Diagnostics:
//   condition number = sigma_max / sigma_min of the normalized design matrix (the one solved), and
//   of the raw design in mm for information (it is what the seed's form would solve);
//   residual_i  = measured_i - dE(X_i, Y_i), um;
//   LOO error_i = measured_i - prediction at i of the fit without point i, um, computed exactly
//                 by the hat-matrix identity r_i / (1 - h_ii), h_ii = ||row i of the thin Q||^2;
//                 undefined (NaN, JSON null) where 1 - h_ii < 1e-9 (the other points do not
//                 determine a cubic), which is every point when there are exactly 10.
#include <array>
#include <vector>

#include "surface/points.h"

namespace whirl::surface {

inline constexpr int kCubicTerms = 10;
/// Exponents (i of X, j of Y) of term k = 0..9 in the order above.
inline constexpr std::array<std::array<int, 2>, kCubicTerms> kCubicExponents = {
    {{0, 0}, {1, 0}, {0, 1}, {2, 0}, {1, 1}, {0, 2}, {3, 0}, {2, 1}, {1, 2}, {0, 3}}};

struct CubicSurface {
  std::array<double, kCubicTerms> b{};  ///< coefficients in u, v (um)
  double x_center_mm = 0, y_center_mm = 0;
  double x_half_range_mm = 1, y_half_range_mm = 1;  ///< > 0
  /// dE at (X, Y), um. Defined everywhere (extrapolation is the caller's decision).
  double Evaluate(double x_mm, double y_mm) const;
  /// a0..a9 of the seed's form in X, Y (mm): a_k in um / mm^(i+j).
  std::array<double, kCubicTerms> CoefficientsMm() const;
};

/// The 10 term values at (u, v) in the order above.
std::array<double, kCubicTerms> CubicTerms(double u, double v);

struct CubicFit {
  CubicSurface surface;
  double condition_number = 0;       ///< normalized design, sigma_max / sigma_min
  double condition_number_mm = 0;    ///< raw design in mm (for information)
  std::vector<double> fitted_um;     ///< dE at each point
  std::vector<double> residual_um;   ///< measured - fitted
  std::vector<double> leverage;      ///< h_ii
  std::vector<double> loo_error_um;  ///< measured - leave-one-out prediction (NaN: undefined)
};

/// Least-squares fit of the 10 coefficients. InputError as stated above.
CubicFit FitCubic(const std::vector<SurfacePoint>& points);

}  // namespace whirl::surface
