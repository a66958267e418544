#include "surface/bspline.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "core/csv.h"
#include "core/error.h"

namespace whirl::surface {
namespace {

std::string Mm(double x) { return FormatNumber(x) + " mm"; }

void CheckDegree(int degree) {
  if (degree < 1 || degree > kMaxDegree)
    throw InputError("B-spline degree " + std::to_string(degree) + " is outside 1.." +
                     std::to_string(kMaxDegree));
}

void CheckLines(std::size_t count, int degree, const char* what) {
  if (count < static_cast<std::size_t>(degree) + 1)
    throw InputError("B-spline surface: " + std::to_string(count) + " " + what + ", degree " +
                     std::to_string(degree) +
                     " needs at least degree + 1 = " + std::to_string(degree + 1));
  if (count > kMaxGridLines)
    throw InputError("B-spline surface: " + std::to_string(count) + " " + what +
                     ", more than the limit of " + std::to_string(kMaxGridLines));
}

// Distinct coordinates (within kSamePositionMm), increasing.
std::vector<double> Lines(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  std::vector<double> lines;
  for (double x : v)
    if (lines.empty() || x - lines.back() > kSamePositionMm) lines.push_back(x);
  return lines;
}

std::size_t LineIndex(const std::vector<double>& lines, double x) {
  const auto it = std::lower_bound(lines.begin(), lines.end(), x - kSamePositionMm);
  return static_cast<std::size_t>(it - lines.begin());
}

// Collocation matrix B(c, j) = N_{j,p}(coords[c]).
Eigen::MatrixXd Collocation(const std::vector<double>& knots, int p,
                            const std::vector<double>& coords) {
  const auto n = static_cast<Eigen::Index>(coords.size());
  Eigen::MatrixXd b(n, n);
  for (Eigen::Index c = 0; c < n; ++c) b.row(c) = BasisRow(knots, p, coords[c]).transpose();
  return b;
}

double Condition1(const Eigen::MatrixXd& b) {
  const Eigen::MatrixXd inv = b.partialPivLu().inverse();
  return b.cwiseAbs().colwise().sum().maxCoeff() * inv.cwiseAbs().colwise().sum().maxCoeff();
}

Grid WithoutRow(const Grid& g, std::size_t row) {
  Grid r{g.grid_x, {}, Eigen::MatrixXd(g.values.rows() - 1, g.values.cols())};
  for (std::size_t i = 0, k = 0; i < g.grid_y.size(); ++i)
    if (i != row) {
      r.grid_y.push_back(g.grid_y[i]);
      r.values.row(static_cast<Eigen::Index>(k++)) = g.values.row(static_cast<Eigen::Index>(i));
    }
  return r;
}

Grid Transposed(const Grid& g) { return {g.grid_y, g.grid_x, g.values.transpose()}; }

// Predictions at every node from the grids without its row; NaN where not defined.
Eigen::MatrixXd RowDropPredictions(const Grid& g, int degree) {
  const auto m = static_cast<Eigen::Index>(g.grid_y.size());
  const auto n = static_cast<Eigen::Index>(g.grid_x.size());
  Eigen::MatrixXd pred = Eigen::MatrixXd::Constant(m, n, NAN);
  if (m - 1 < degree + 1) return pred;
  for (Eigen::Index i = 1; i + 1 < m; ++i) {
    const BsplineSurface s = FitBspline(WithoutRow(g, static_cast<std::size_t>(i)), degree);
    for (Eigen::Index j = 0; j < n; ++j)
      pred(i, j) =
          s.Evaluate(g.grid_x[static_cast<std::size_t>(j)], g.grid_y[static_cast<std::size_t>(i)]);
  }
  return pred;
}

}  // namespace

std::vector<double> ClampedAveragedKnots(const std::vector<double>& coords, int degree) {
  CheckDegree(degree);
  const int n = static_cast<int>(coords.size());
  if (n < degree + 1)
    throw InputError("knot vector: " + std::to_string(n) + " coordinates, degree " +
                     std::to_string(degree) + " needs at least " + std::to_string(degree + 1));
  for (int i = 1; i < n; ++i)
    if (!(coords[i] > coords[i - 1]))
      throw InputError("knot vector: coordinates must increase strictly (" + Mm(coords[i]) +
                       " after " + Mm(coords[i - 1]) + ")");
  std::vector<double> t(static_cast<std::size_t>(n + degree + 1));
  for (int k = 0; k <= degree; ++k) {
    t[k] = coords.front();
    t[n + k] = coords.back();
  }
  for (int j = 1; j <= n - degree - 1; ++j) {
    double sum = 0;
    for (int i = j; i <= j + degree - 1; ++i) sum += coords[i];
    t[j + degree] = sum / degree;
  }
  return t;
}

double BasisFunction(const std::vector<double>& knots, int j, int p, double x) {
  const int n = static_cast<int>(knots.size()) - p - 1;
  if (x == knots.back()) return j == n - 1 ? 1.0 : 0.0;  // seed note 2: upper end
  if (p == 0) return knots[j] <= x && x < knots[j + 1] ? 1.0 : 0.0;
  double value = 0;
  const double d1 = knots[j + p] - knots[j];
  const double d2 = knots[j + p + 1] - knots[j + 1];
  // Seed note 1: a term with a zero denominator is 0.
  if (d1 != 0) value += (x - knots[j]) / d1 * BasisFunction(knots, j, p - 1, x);
  if (d2 != 0) value += (knots[j + p + 1] - x) / d2 * BasisFunction(knots, j + 1, p - 1, x);
  return value;
}

Eigen::VectorXd BasisRow(const std::vector<double>& knots, int p, double x) {
  const int n = static_cast<int>(knots.size()) - p - 1;
  Eigen::VectorXd row(n);
  for (int j = 0; j < n; ++j) row(j) = BasisFunction(knots, j, p, x);
  return row;
}

Grid ArrangeGrid(const std::vector<SurfacePoint>& points) {
  std::vector<double> xs, ys;
  for (const auto& p : points) xs.push_back(p.x_mm), ys.push_back(p.y_mm);
  Grid g{Lines(xs), Lines(ys), {}};
  const std::size_t m = g.grid_y.size(), n = g.grid_x.size();
  if (m > kMaxGridLines || n > kMaxGridLines)
    throw InputError("B-spline surface: " + std::to_string(m) + " x " + std::to_string(n) +
                     " grid lines, more than the limit of " + std::to_string(kMaxGridLines));
  g.values =
      Eigen::MatrixXd::Constant(static_cast<Eigen::Index>(m), static_cast<Eigen::Index>(n), NAN);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(LineIndex(g.grid_y, points[k].y_mm));
    const auto j = static_cast<Eigen::Index>(LineIndex(g.grid_x, points[k].x_mm));
    if (!std::isnan(g.values(i, j)))
      throw InputError("B-spline surface: point " + std::to_string(k + 1) + " (x " +
                       Mm(points[k].x_mm) + ", y " + Mm(points[k].y_mm) +
                       ") measures a grid node twice; the grid needs one value per node");
    g.values(i, j) = points[k].error_um;
  }
  for (Eigen::Index i = 0; i < g.values.rows(); ++i)
    for (Eigen::Index j = 0; j < g.values.cols(); ++j)
      if (std::isnan(g.values(i, j)))
        throw InputError("B-spline surface: irregular grid: the " + std::to_string(points.size()) +
                         " points span " + std::to_string(m) + " rows x " + std::to_string(n) +
                         " columns but node (x " + Mm(g.grid_x[static_cast<std::size_t>(j)]) +
                         ", y " + Mm(g.grid_y[static_cast<std::size_t>(i)]) +
                         ") has no point; the seed's interpolation needs a complete rectangular "
                         "grid (use --method cubic for scattered points)");
  return g;
}

bool BsplineSurface::Contains(double x_mm, double y_mm) const {
  return x_mm >= grid_x.front() && x_mm <= grid_x.back() && y_mm >= grid_y.front() &&
         y_mm <= grid_y.back();
}

double BsplineSurface::Evaluate(double x_mm, double y_mm) const {
  if (!Contains(x_mm, y_mm))
    throw InputError("B-spline surface: position (x " + Mm(x_mm) + ", y " + Mm(y_mm) +
                     ") is outside the measured grid [" + Mm(grid_x.front()) + ", " +
                     Mm(grid_x.back()) + "] x [" + Mm(grid_y.front()) + ", " + Mm(grid_y.back()) +
                     "]; the interpolation does not extrapolate");
  const Eigen::VectorXd nx = BasisRow(knots_x, degree, x_mm);
  const Eigen::VectorXd ny = BasisRow(knots_y, degree, y_mm);
  return ny.dot(weights * nx);
}

BsplineSurface FitBspline(const Grid& grid, int degree) {
  CheckDegree(degree);
  CheckLines(grid.grid_x.size(), degree, "columns (distinct X)");
  CheckLines(grid.grid_y.size(), degree, "rows (distinct Y)");
  BsplineSurface s;
  s.degree = degree;
  s.grid_x = grid.grid_x;
  s.grid_y = grid.grid_y;
  s.knots_x = ClampedAveragedKnots(grid.grid_x, degree);
  s.knots_y = ClampedAveragedKnots(grid.grid_y, degree);
  const Eigen::MatrixXd bx = Collocation(s.knots_x, degree, grid.grid_x);
  const Eigen::MatrixXd by = Collocation(s.knots_y, degree, grid.grid_y);
  // B_Y G B_X^T = E  =>  G = B_Y^-1 E B_X^-T.
  const Eigen::MatrixXd h = by.partialPivLu().solve(grid.values);  // G B_X^T
  s.weights = bx.partialPivLu().solve(h.transpose()).transpose();  // G
  return s;
}

BsplineFit FitBsplinePoints(const std::vector<SurfacePoint>& points, int degree) {
  BsplineFit fit;
  fit.grid = ArrangeGrid(points);
  fit.surface = FitBspline(fit.grid, degree);
  fit.condition_x = Condition1(Collocation(fit.surface.knots_x, degree, fit.grid.grid_x));
  fit.condition_y = Condition1(Collocation(fit.surface.knots_y, degree, fit.grid.grid_y));
  const Eigen::MatrixXd by_row = RowDropPredictions(fit.grid, degree);
  const Eigen::MatrixXd by_col = RowDropPredictions(Transposed(fit.grid), degree).transpose();
  for (const auto& p : points) {
    const std::size_t iy = LineIndex(fit.grid.grid_y, p.y_mm),
                      jx = LineIndex(fit.grid.grid_x, p.x_mm);
    // At the node's grid coordinates (a point may sit up to kSamePositionMm beside its line).
    fit.residual_um.push_back(p.error_um -
                              fit.surface.Evaluate(fit.grid.grid_x[jx], fit.grid.grid_y[iy]));
    const auto i = static_cast<Eigen::Index>(iy);
    const auto j = static_cast<Eigen::Index>(jx);
    double sum = 0;
    int count = 0;
    for (double v : {by_row(i, j), by_col(i, j)})
      if (!std::isnan(v)) sum += v, ++count;
    fit.loo_error_um.push_back(count ? p.error_um - sum / count : NAN);
  }
  return fit;
}

}  // namespace whirl::surface
