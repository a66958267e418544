#pragma once
// Tensor-product B-spline surface interpolating a rectangular grid (the worktable chapter's
// "B-spline surface interpolation", its eqs. 7-23 to 7-29; the knot formulas did not survive in
// the text, so the construction below is the project's, stated in full).
//
// Grid: M rows (Y_1 < ... < Y_M) and N columns (X_1 < ... < X_N); one measured error per node
// E(X_j, Y_i). Refused (InputError): a point set that is not a complete rectangular grid (a node
// missing or measured twice, a point off the grid lines), fewer than p + 1 rows or columns (the
// seed's condition N + p + 1 >= 2 (p + 1)), more than kMaxGridLines rows or columns, and a degree
// outside 1..kMaxDegree. Coordinates within kSamePositionMm are the same grid line.
//
// Knots (clamped at both ends, interior knots by averaging; Piegl & Tiller, The NURBS Book, 2nd
// ed., eq. 9.8), for the coordinates x_0 < ... < x_{n-1} of one direction and degree p, n + p + 1
// knots (0-based):
//   t_0 = ... = t_p = x_0,     t_n = ... = t_{n+p} = x_{n-1},
//   t_{j+p} = (x_j + x_{j+1} + ... + x_{j+p-1}) / p      for j = 1 .. n - p - 1.
// Then t_j < x_j < t_{j+p+1} wherever these knots are interior (the Schoenberg-Whitney condition),
// so the collocation matrix below is nonsingular. The same rule gives U_X from the X_j and U_Y
// from the Y_i.
//
// Basis (Cox-de Boor, seed eqs. 7-23/7-24):
//   N_{j,0}(x) = 1 if t_j <= x < t_{j+1}, else 0
//   N_{j,k}(x) = (x - t_j) / (t_{j+k} - t_j) N_{j,k-1}(x)
//              + (t_{j+k+1} - x) / (t_{j+k+1} - t_{j+1}) N_{j+1,k-1}(x),
// a term whose denominator is 0 (repeated knots) is taken as 0 (seed note 1). At the upper end
// x = x_{n-1} every N_{j,0} is 0 (half-open intervals), so the last basis function N_{n-1,p} is
// forced to 1 there (seed note 2); the others are 0 there.
//
// Surface (seed eq. 7-25):  S(X, Y) = sum_{i=1..M} sum_{j=1..N} G_{i,j} N_{i,p}(Y) N_{j,p}(X).
// Weights: the M x N interpolation equations S(X_j, Y_i) = E(X_j, Y_i) form the linear system
//   (B_Y kron B_X) vec(G) = vec(E),  B_X(c, j) = N_{j,p}(X_c),  B_Y(r, i) = N_{i,p}(Y_r),
// i.e. B_Y G B_X^T = E; it is solved as two small systems (LU with partial pivoting of B_Y and
// B_X), the same solution as the MN x MN system at a fraction of the cost.
// Evaluation outside [X_1, X_N] x [Y_1, Y_M] is refused: the seed allows no extrapolation.
// Reproduction: for p >= the degree in each variable, the surface reproduces every polynomial
// X^a Y^b with a, b <= p exactly (both are in the tensor spline space and interpolation in it is
// unique).
#include <Eigen/Core>
#include <vector>

#include "surface/points.h"

namespace whirl::surface {

inline constexpr int kMaxDegree = 5;
inline constexpr std::size_t kMaxGridLines = 200;  ///< rows or columns of a grid

/// Knot vector of the statement above; InputError if coords has fewer than degree + 1 values or
/// does not increase strictly.
std::vector<double> ClampedAveragedKnots(const std::vector<double>& coords, int degree);

/// N_{j,p}(x) by the recursion above (j 0-based, 0 <= j < knots.size() - p - 1), including the
/// upper-end rule for the last function. x outside [knots.front(), knots.back()] gives 0.
double BasisFunction(const std::vector<double>& knots, int j, int p, double x);

/// All n = knots.size() - p - 1 basis values at x.
Eigen::VectorXd BasisRow(const std::vector<double>& knots, int p, double x);

/// Points arranged as a grid: values(i, j) = E at (grid_x[j], grid_y[i]).
struct Grid {
  std::vector<double> grid_x;  ///< N column coordinates, increasing, mm
  std::vector<double> grid_y;  ///< M row coordinates, increasing, mm
  Eigen::MatrixXd values;      ///< M x N errors, um
};

/// Arranges points into a complete rectangular grid; InputError naming the rule otherwise.
Grid ArrangeGrid(const std::vector<SurfacePoint>& points);

struct BsplineSurface {
  int degree = 3;
  std::vector<double> grid_x, grid_y;    ///< X_1..X_N, Y_1..Y_M, mm
  std::vector<double> knots_x, knots_y;  ///< U_X (N + p + 1), U_Y (M + p + 1)
  Eigen::MatrixXd weights;               ///< G, M x N, um
  /// S(X, Y), um; InputError outside the grid's rectangle (no extrapolation).
  double Evaluate(double x_mm, double y_mm) const;
  bool Contains(double x_mm, double y_mm) const;
};

/// Interpolating surface of a grid. InputError for a degree outside 1..kMaxDegree, fewer than
/// degree + 1 rows or columns, more than kMaxGridLines.
BsplineSurface FitBspline(const Grid& grid, int degree);

struct BsplineFit {
  BsplineSurface surface;
  Grid grid;
  double condition_x = 0, condition_y = 0;  ///< 1-norm condition numbers of B_X and B_Y
  std::vector<double> residual_um;          ///< per input point: measured - S (about 1e-12)
  /// Per input point, measured - leave-one-out prediction (NaN: undefined). A point cannot be
  /// left out of a rectangular grid alone, so its prediction is the mean of the predictions of
  /// the two largest grids without it: the grid without its row and the grid without its column.
  /// Each is used only where the point stays inside the reduced grid (its row/column is not the
  /// first or last) and the reduced grid keeps degree + 1 lines. A corner is never predicted.
  /// This leaves out a whole line (M or N points), a harder test than the cubic's single point.
  std::vector<double> loo_error_um;
};

BsplineFit FitBsplinePoints(const std::vector<SurfacePoint>& points, int degree);

}  // namespace whirl::surface
