#include "drift/regression.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

namespace whirl::drift {
namespace {

Eigen::MatrixXd WithIntercept(const Eigen::MatrixXd& x) {
  Eigen::MatrixXd x1(x.rows(), x.cols() + 1);
  x1.col(0).setOnes();
  x1.rightCols(x.cols()) = x;
  return x1;
}

// Columns scaled to unit norm before the QR, so the rank test does not depend on units.
struct Solved {
  Eigen::VectorXd b;
  Eigen::MatrixXd xtx_inverse;
};

Solved Solve(const Eigen::MatrixXd& x1, const Eigen::VectorXd& y) {
  Eigen::VectorXd scale = x1.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < scale.size(); ++j)
    if (!(scale(j) > 0)) scale(j) = 1;
  const Eigen::MatrixXd xs = x1 * scale.cwiseInverse().asDiagonal();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(xs);
  qr.setThreshold(1e-12);
  if (qr.rank() < xs.cols())
    throw InputError("regression: the regressors (with the intercept) have rank " +
                     std::to_string(qr.rank()) + " of " + std::to_string(xs.cols()) +
                     ": some are collinear (a constant sensor, or the same series twice)");
  Solved s;
  s.b = scale.cwiseInverse().asDiagonal() * qr.solve(y);
  // (X1'X1)^-1 = S^-1 (Xs'Xs)^-1 S^-1 with Xs'Xs = P R'R P'.
  const Eigen::Index p = xs.cols();
  const Eigen::MatrixXd r = qr.matrixR().topLeftCorner(p, p).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inv =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::MatrixXd inner =
      qr.colsPermutation() * (r_inv * r_inv.transpose()) * qr.colsPermutation().transpose();
  s.xtx_inverse = scale.cwiseInverse().asDiagonal() * inner * scale.cwiseInverse().asDiagonal();
  return s;
}

double RSquared(const Eigen::VectorXd& y, const Eigen::VectorXd& residual) {
  const double tss = (y.array() - y.mean()).square().sum();
  const double rss = residual.squaredNorm();
  if (tss <= 0) return rss <= 0 ? 1.0 : 0.0;
  return 1.0 - rss / tss;
}

}  // namespace

LinearFit FitLinear(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  const Eigen::Index n = x.rows(), p = x.cols();
  if (y.size() != n) throw InputError("regression: x and y have different sample counts");
  if (n <= p + 1)
    throw InputError("regression: " + std::to_string(n) + " samples for " + std::to_string(p) +
                     " regressors and an intercept: need more than " + std::to_string(p + 1));
  if (!x.allFinite() || !y.allFinite()) throw InputError("regression: a value is not finite");
  const Eigen::MatrixXd x1 = WithIntercept(x);
  const Solved s = Solve(x1, y);
  LinearFit f;
  f.coefficients = s.b;
  f.xtx_inverse = s.xtx_inverse;
  const Eigen::VectorXd residual = y - x1 * s.b;
  f.samples = static_cast<int>(n);
  f.degrees_of_freedom = static_cast<int>(n - p - 1);
  f.residual_std_um = std::sqrt(residual.squaredNorm() / f.degrees_of_freedom);
  f.covariance = f.residual_std_um * f.residual_std_um * s.xtx_inverse;
  f.standard_errors = f.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  f.r_squared = RSquared(y, residual);
  f.vif = VarianceInflation(x);
  return f;
}

Eigen::VectorXd LeastSquaresCoefficients(const Eigen::MatrixXd& x, const Eigen::VectorXd& y) {
  const Eigen::MatrixXd x1 = WithIntercept(x);
  Eigen::VectorXd scale = x1.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < scale.size(); ++j)
    if (!(scale(j) > 0)) scale(j) = 1;
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(x1 *
                                                              scale.cwiseInverse().asDiagonal());
  cod.setThreshold(1e-12);
  return scale.cwiseInverse().asDiagonal() * cod.solve(y);
}

Eigen::VectorXd EvaluateLinear(const Eigen::VectorXd& coefficients, const Eigen::MatrixXd& x) {
  return (x * coefficients.tail(coefficients.size() - 1)).array() + coefficients(0);
}

Eigen::VectorXd VarianceInflation(const Eigen::MatrixXd& x) {
  const Eigen::Index p = x.cols();
  Eigen::VectorXd vif = Eigen::VectorXd::Ones(p);
  if (p < 2) return vif;
  for (Eigen::Index j = 0; j < p; ++j) {
    Eigen::MatrixXd others(x.rows(), p - 1);
    for (Eigen::Index k = 0, c = 0; k < p; ++k)
      if (k != j) others.col(c++) = x.col(k);
    const Eigen::MatrixXd o1 = WithIntercept(others);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(o1);
    const Eigen::VectorXd res = x.col(j) - o1 * qr.solve(x.col(j));
    const double r2 = RSquared(x.col(j), res);
    vif(j) = r2 < 1 ? 1.0 / (1.0 - r2) : std::numeric_limits<double>::infinity();
  }
  return vif;
}

Eigen::VectorXd FirstOrderLag(const Eigen::VectorXd& x, const std::vector<double>& t, double tau) {
  if (!(tau > 0)) throw InputError("lag time constant " + std::to_string(tau) + ": must be > 0");
  Eigen::VectorXd y(x.size());
  if (x.size() == 0) return y;
  y(0) = x(0);
  for (Eigen::Index k = 1; k < x.size(); ++k) {
    const double a =
        1.0 -
        std::exp(-(t[static_cast<std::size_t>(k)] - t[static_cast<std::size_t>(k - 1)]) / tau);
    y(k) = y(k - 1) + a * (x(k) - y(k - 1));
  }
  return y;
}

}  // namespace whirl::drift
