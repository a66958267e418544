#include "drift/regression.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"
#include "core/numbers.h"

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

namespace whirl::drift {
namespace {

struct WarmUpData {
  const std::vector<std::vector<double>>& t;
  const std::vector<Eigen::VectorXd>& e;
  const Eigen::MatrixXd& fixed;
  Eigen::Index rows = 0;
};

// Stacked design [elapsed lags] of every run for time constants `taus`.
Eigen::MatrixXd WarmUpDesign(const WarmUpData& d, const std::vector<double>& taus) {
  const Eigen::Index c = d.fixed.cols();
  Eigen::MatrixXd x(d.rows, c + static_cast<Eigen::Index>(taus.size()));
  if (c > 0) x.leftCols(c) = d.fixed;
  Eigen::Index at = 0;
  for (const auto& t : d.t) {
    for (std::size_t k = 0; k < t.size(); ++k, ++at)
      for (std::size_t j = 0; j < taus.size(); ++j)
        x(at, c + static_cast<Eigen::Index>(j)) = 1.0 - std::exp(-t[k] / taus[j]);
  }
  return x;
}

Eigen::VectorXd WarmUpTarget(const WarmUpData& d) {
  Eigen::VectorXd y(d.rows);
  Eigen::Index at = 0;
  for (const auto& e : d.e) {
    y.segment(at, e.size()) = e;
    at += e.size();
  }
  return y;
}

// Least squares of y on [1 design(taus)]: the residual sum of squares, coefficients in *b.
double LeastSquaresSse(const WarmUpData& d, const Eigen::VectorXd& y,
                       const std::vector<double>& taus, Eigen::VectorXd* b) {
  const Eigen::MatrixXd x = WarmUpDesign(d, taus);
  *b = LeastSquaresCoefficients(x, y);
  return (y - EvaluateLinear(*b, x)).squaredNorm();
}

// The projected residual sum of squares: the gains by least squares for these taus, the warm-up
// gains held to one sign (FitWarmUp). Two gains of opposite sign: the optimum of the convex
// problem on the closed orthants lies on their boundary, a gain of 0, so it is the better of each
// term alone (the other's gain set to 0 in *b).
double ProjectedSse(const WarmUpData& d, const Eigen::VectorXd& y, const std::vector<double>& taus,
                    Eigen::VectorXd* b) {
  const double sse = LeastSquaresSse(d, y, taus, b);
  const Eigen::Index c = 1 + d.fixed.cols();
  if (taus.size() != 2 || (*b)(c) * (*b)(c + 1) >= 0) return sse;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t drop = 0; drop < 2; ++drop) {
    Eigen::VectorXd one;
    const double s = LeastSquaresSse(d, y, {taus[1 - drop]}, &one);
    if (!(s < best)) continue;
    best = s;
    b->head(c) = one.head(c);
    (*b)(c + static_cast<Eigen::Index>(1 - drop)) = one(c);
    (*b)(c + static_cast<Eigen::Index>(drop)) = 0.0;
  }
  return best;
}

// Golden-section minimum of f over log tau in [lo, hi] (Kiefer, "Sequential minimax search for a
// maximum"), 30 steps: a bracket of 1e-6 of the log range.
template <typename F>
double GoldenLog(F f, double lo, double hi) {
  const double g = (std::sqrt(5.0) - 1) / 2;
  double a = std::log(lo), c = std::log(hi);
  double x1 = c - g * (c - a), x2 = a + g * (c - a);
  double f1 = f(std::exp(x1)), f2 = f(std::exp(x2));
  for (int i = 0; i < 30; ++i) {
    if (f1 <= f2) {
      c = x2, x2 = x1, f2 = f1, x1 = c - g * (c - a), f1 = f(std::exp(x1));
    } else {
      a = x1, x1 = x2, f1 = f2, x2 = a + g * (c - a), f2 = f(std::exp(x2));
    }
  }
  return std::exp(f1 <= f2 ? x1 : x2);
}

// The longest run's time since its start: the trained time range.
double LongestSpan(const WarmUpData& d) {
  double longest = 0;
  for (const auto& t : d.t)
    if (!t.empty()) longest = std::max(longest, t.back());
  return longest;
}

std::vector<double> LogGrid(const WarmUpData& d) {
  std::vector<double> steps;
  for (const auto& t : d.t)
    for (std::size_t k = 1; k < t.size(); ++k) steps.push_back(t[k] - t[k - 1]);
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                   steps.end());
  const double lo = 2 * steps[steps.size() / 2];
  const double hi = std::max(kMaxWarmUpTauPerSpan * LongestSpan(d), lo);
  std::vector<double> grid(41);
  for (int i = 0; i < 41; ++i) grid[static_cast<std::size_t>(i)] = lo * std::pow(hi / lo, i / 40.0);
  return grid;
}

// Best grid point (one term) or pair with tau_2 >= 3 tau_1 (two terms), as grid indices.
std::vector<std::size_t> GridSearch(const WarmUpData& d, const Eigen::VectorXd& y,
                                    const std::vector<double>& grid, int terms) {
  double best = std::numeric_limits<double>::infinity();
  std::vector<std::size_t> at;
  Eigen::VectorXd b;
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (terms == 1) {
      const double sse = ProjectedSse(d, y, {grid[i]}, &b);
      if (sse < best) best = sse, at = {i};
      continue;
    }
    for (std::size_t k = i + 1; k < grid.size(); ++k) {
      if (grid[k] < 3 * grid[i]) continue;
      const double sse = ProjectedSse(d, y, {grid[i], grid[k]}, &b);
      if (sse < best) best = sse, at = {i, k};
    }
  }
  return at;
}

}  // namespace

WarmUpFit FitWarmUp(const std::vector<std::vector<double>>& times,
                    const std::vector<Eigen::VectorXd>& errors, int terms,
                    const Eigen::MatrixXd& fixed) {
  if (terms < 1 || terms > 2)
    throw InputError("warm-up model: " + std::to_string(terms) + " terms: must be 1 or 2");
  WarmUpData d{times, errors, fixed};
  bool long_enough = false;
  for (std::size_t i = 0; i < times.size(); ++i) {
    d.rows += static_cast<Eigen::Index>(times[i].size());
    long_enough = long_enough || times[i].size() >= 3;
  }
  if (!long_enough) throw InputError("warm-up model: no run has 3 samples");
  if (fixed.cols() > 0 && fixed.rows() != d.rows)
    throw InputError("warm-up model: the fixed columns need one row per sample");
  const Eigen::VectorXd y = WarmUpTarget(d);
  const std::vector<double> grid = LogGrid(d);
  const std::vector<std::size_t> at = GridSearch(d, y, grid, terms);
  if (at.empty()) {  // two terms 3 apart do not fit between two sample steps and the span
    WarmUpFit one = FitWarmUp(times, errors, 1, fixed);
    one.note = "the trained span is too short for two time constants: one term" +
               std::string(one.note.empty() ? "" : "; ") + one.note;
    return one;
  }
  std::vector<double> taus;
  for (std::size_t i : at) taus.push_back(grid[i]);
  Eigen::VectorXd b;
  for (std::size_t j = 0; j < taus.size(); ++j) {  // refine each tau between its neighbours
    const std::size_t i = at[j];
    const double lo = grid[i > 0 ? i - 1 : 0], hi = grid[std::min(i + 1, grid.size() - 1)];
    std::vector<double> trial = taus;
    const double lower = j == 1 ? std::max(lo, 3 * taus[0]) : lo;
    const double upper = j == 0 && taus.size() == 2 ? std::min(hi, taus[1] / 3) : hi;
    if (!(upper > lower)) continue;
    taus[j] = GoldenLog(
        [&](double tau) {
          trial[j] = tau;
          return ProjectedSse(d, y, trial, &b);
        },
        lower, upper);
  }
  WarmUpFit f;
  f.span = LongestSpan(d);
  f.rmse_um = std::sqrt(ProjectedSse(d, y, taus, &f.coefficients) / static_cast<double>(d.rows));
  const Eigen::Index c = 1 + fixed.cols();
  std::vector<std::size_t> kept_at = at;
  if (taus.size() == 2 && (f.coefficients(c) == 0.0 || f.coefficients(c + 1) == 0.0)) {
    const std::size_t zero = f.coefficients(c) == 0.0 ? 0 : 1;  // the term held at 0: dropped
    taus.erase(taus.begin() + static_cast<std::ptrdiff_t>(zero));
    kept_at.erase(kept_at.begin() + static_cast<std::ptrdiff_t>(zero));
    Eigen::VectorXd kept(c + 1);
    kept.head(c) = f.coefficients.head(c);
    kept(c) = f.coefficients(c + 1 - static_cast<Eigen::Index>(zero));
    f.coefficients = kept;
    f.note = "two terms would need gains of opposite sign: one term kept";
  }
  f.time_constants = taus;
  if (kept_at.back() + 1 == grid.size() && grid.back() > grid.front()) {
    f.identified = false;
    f.note += std::string(f.note.empty() ? "" : "; ") + "tau at the training span (" +
              FormatSignificant(f.span, 4) +
              "): the warm-up is slower than the training runs show; its plateau is a bound, "
              "not a measured level";
  }
  return f;
}

}  // namespace whirl::drift
