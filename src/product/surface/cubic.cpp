#include "surface/cubic.h"

#include <Eigen/Dense>
#include <cmath>

#include "core/error.h"

namespace whirl::surface {
namespace {

double Binomial(int n, int k) {
  double c = 1;
  for (int i = 1; i <= k; ++i) c = c * (n - k + i) / i;
  return c;
}

int TermIndex(int i, int j) {
  for (int k = 0; k < kCubicTerms; ++k)
    if (kCubicExponents[k][0] == i && kCubicExponents[k][1] == j) return k;
  return -1;
}

double ConditionNumber(const Eigen::MatrixXd& a) {
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(a);
  const auto& s = svd.singularValues();
  return s(s.size() - 1) > 0 ? s(0) / s(s.size() - 1) : INFINITY;
}

CubicSurface Frame(const std::vector<SurfacePoint>& points) {
  const Bounds b = BoundsOf(points);
  CubicSurface s;
  s.x_center_mm = 0.5 * (b.x_min_mm + b.x_max_mm);
  s.y_center_mm = 0.5 * (b.y_min_mm + b.y_max_mm);
  // A zero width leaves the design rank-deficient; the rank check names it, so avoid a 0 divisor.
  s.x_half_range_mm = std::max(0.5 * (b.x_max_mm - b.x_min_mm), kSamePositionMm);
  s.y_half_range_mm = std::max(0.5 * (b.y_max_mm - b.y_min_mm), kSamePositionMm);
  return s;
}

Eigen::MatrixXd Design(const std::vector<SurfacePoint>& points, const CubicSurface& frame) {
  Eigen::MatrixXd a(static_cast<Eigen::Index>(points.size()), kCubicTerms);
  for (std::size_t r = 0; r < points.size(); ++r) {
    const auto t = CubicTerms((points[r].x_mm - frame.x_center_mm) / frame.x_half_range_mm,
                              (points[r].y_mm - frame.y_center_mm) / frame.y_half_range_mm);
    for (int k = 0; k < kCubicTerms; ++k) a(static_cast<Eigen::Index>(r), k) = t[k];
  }
  return a;
}

}  // namespace

std::array<double, kCubicTerms> CubicTerms(double u, double v) {
  std::array<double, kCubicTerms> t{};
  for (int k = 0; k < kCubicTerms; ++k)
    t[k] = std::pow(u, kCubicExponents[k][0]) * std::pow(v, kCubicExponents[k][1]);
  return t;
}

double CubicSurface::Evaluate(double x_mm, double y_mm) const {
  const auto t =
      CubicTerms((x_mm - x_center_mm) / x_half_range_mm, (y_mm - y_center_mm) / y_half_range_mm);
  double e = 0;
  for (int k = 0; k < kCubicTerms; ++k) e += b[k] * t[k];
  return e;
}

// u = al X + be with al = 1/hx, be = -xc/hx: u^i = sum_k C(i,k) al^k be^(i-k) X^k (same for v).
std::array<double, kCubicTerms> CubicSurface::CoefficientsMm() const {
  const double al = 1 / x_half_range_mm, be = -x_center_mm / x_half_range_mm;
  const double ga = 1 / y_half_range_mm, de = -y_center_mm / y_half_range_mm;
  std::array<double, kCubicTerms> a{};
  for (int t = 0; t < kCubicTerms; ++t) {
    const int i = kCubicExponents[t][0], j = kCubicExponents[t][1];
    for (int k = 0; k <= i; ++k)
      for (int l = 0; l <= j; ++l)
        a[TermIndex(k, l)] += b[t] * Binomial(i, k) * std::pow(al, k) * std::pow(be, i - k) *
                              Binomial(j, l) * std::pow(ga, l) * std::pow(de, j - l);
  }
  return a;
}

CubicFit FitCubic(const std::vector<SurfacePoint>& points) {
  const std::size_t distinct = CountDistinctPositions(points);
  if (distinct < static_cast<std::size_t>(kCubicTerms))
    throw InputError("cubic surface: " + std::to_string(distinct) +
                     " distinct positions, the 10 coefficients need at least 10");
  CubicFit fit;
  fit.surface = Frame(points);
  const Eigen::MatrixXd a = Design(points, fit.surface);
  Eigen::VectorXd e(a.rows());
  for (Eigen::Index r = 0; r < a.rows(); ++r) e(r) = points[static_cast<std::size_t>(r)].error_um;
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(a);
  qr.setThreshold(1e-10);
  if (qr.rank() < kCubicTerms)
    throw InputError("cubic surface: the " + std::to_string(distinct) +
                     " positions determine only " + std::to_string(qr.rank()) +
                     " of the 10 coefficients (they lie on one cubic curve, e.g. a few lines); "
                     "measure points spread over the table");
  const Eigen::VectorXd b = qr.solve(e);
  for (int k = 0; k < kCubicTerms; ++k) fit.surface.b[k] = b(k);
  fit.condition_number = ConditionNumber(a);
  CubicSurface raw;  // X, Y themselves: centre 0, half range 1
  raw.x_center_mm = raw.y_center_mm = 0;
  fit.condition_number_mm = ConditionNumber(Design(points, raw));
  const Eigen::MatrixXd q = qr.householderQ() * Eigen::MatrixXd::Identity(a.rows(), kCubicTerms);
  const Eigen::VectorXd fitted = a * b;
  for (Eigen::Index r = 0; r < a.rows(); ++r) {
    const double h = q.row(r).squaredNorm();
    const double res = e(r) - fitted(r);
    fit.fitted_um.push_back(fitted(r));
    fit.residual_um.push_back(res);
    fit.leverage.push_back(h);
    fit.loo_error_um.push_back(1 - h < 1e-9 ? NAN : res / (1 - h));
  }
  return fit;
}

}  // namespace whirl::surface
