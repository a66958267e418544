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

StreamingLeastSquares::StreamingLeastSquares(int regressors)
    : p_(regressors), r_(Eigen::MatrixXd::Zero(regressors + 2, regressors + 2)),
      block_(4096, regressors + 2) {}

void StreamingLeastSquares::Add(const Eigen::Ref<const Eigen::VectorXd>& x, double y) {
  if (filled_ == block_.rows()) Flush();
  block_(filled_, 0) = 1.0;
  block_.row(filled_).segment(1, p_) = x.transpose();
  block_(filled_, p_ + 1) = y;
  finite_ = finite_ && x.allFinite() && std::isfinite(y);
  ++filled_;
  ++n_;
}

void StreamingLeastSquares::Flush() {
  if (filled_ == 0) return;
  const Eigen::Index c = p_ + 2, top = have_r_ ? c : 0;
  Eigen::MatrixXd stack(top + filled_, c);
  if (have_r_) stack.topRows(c) = r_;
  stack.bottomRows(filled_) = block_.topRows(filled_);
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(stack);
  const Eigen::Index k = std::min<Eigen::Index>(stack.rows(), c);
  r_.setZero();
  r_.topRows(k) = qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
  have_r_ = true;
  filled_ = 0;
}

LinearFit StreamingLeastSquares::Fit() {
  Flush();
  const Eigen::Index p = p_;
  if (n_ <= p + 1)
    throw InputError("regression: " + std::to_string(n_) + " samples for " + std::to_string(p) +
                     " regressors and an intercept: need more than " + std::to_string(p + 1));
  if (!finite_) throw InputError("regression: a value is not finite");
  const Eigen::MatrixXd a = r_.leftCols(p + 1);
  const Eigen::VectorXd b = r_.col(p + 1);
  const Solved s = Solve(a, b);
  LinearFit f;
  f.coefficients = s.b;
  f.xtx_inverse = s.xtx_inverse;
  const double rss = (b - a * s.b).squaredNorm();
  const double tss = b.tail(p + 1).squaredNorm();  // below the intercept's row
  f.samples = static_cast<int>(std::min<long long>(n_, std::numeric_limits<int>::max()));
  f.degrees_of_freedom = static_cast<int>(std::min<long long>(n_ - p - 1,
                                                              std::numeric_limits<int>::max()));
  f.residual_std_um = std::sqrt(rss / static_cast<double>(n_ - p - 1));
  f.covariance = f.residual_std_um * f.residual_std_um * s.xtx_inverse;
  f.standard_errors = f.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  f.r_squared = tss <= 0 ? (rss <= 0 ? 1.0 : 0.0) : 1.0 - rss / tss;
  // VIF_j from the centred block: column j of R_22 on the others (no intercept: centred).
  const Eigen::MatrixXd r22 = r_.block(1, 1, p, p);
  f.vif = Eigen::VectorXd::Ones(p);
  for (Eigen::Index j = 0; j < p && p >= 2; ++j) {
    Eigen::MatrixXd others(p, p - 1);
    for (Eigen::Index k = 0, c = 0; k < p; ++k)
      if (k != j) others.col(c++) = r22.col(k);
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(others);
    const double res = (r22.col(j) - others * qr.solve(r22.col(j))).squaredNorm();
    const double tot = r22.col(j).squaredNorm();
    const double r2 = tot <= 0 ? (res <= 0 ? 1.0 : 0.0) : 1.0 - res / tot;
    f.vif(j) = r2 < 1 ? 1.0 / (1.0 - r2) : std::numeric_limits<double>::infinity();
  }
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

// One elapsed-time column 1 - exp(-(t - t0) / tau) with the intercept and the fixed columns
// projected out (Frisch-Waugh-Lovell: the gains' least squares on the projected columns is the
// joint one): g_hat, its squared norm and its product with the projected error.
struct Projected {
  double tau = 0;
  Eigen::VectorXd g;  // projected
  double gg = 0, gy = 0, raw = 0;  // |g_hat|^2, g_hat' y_hat, |g|^2 (the rank test's scale)
};

// The warm-up's least squares for given time constants, fast: the span of [1 fixed] is
// factored once (an orthonormal basis by rank-revealing QR of the unit-norm-scaled columns, the
// threshold of LeastSquaresCoefficients), every time-constant column is projected on its
// complement once, and a candidate's residual sum of squares follows from the projected
// columns' products: O(rows) per new time constant instead of a QR of the whole design.
class WarmUpLeastSquares {
 public:
  WarmUpLeastSquares(const WarmUpData& d, const Eigen::VectorXd& y) : d_(d), y_(y) {
    Eigen::MatrixXd base(d.rows, 1 + d.fixed.cols());
    base.col(0).setOnes();
    if (d.fixed.cols() > 0) base.rightCols(d.fixed.cols()) = d.fixed;
    Eigen::VectorXd scale = base.colwise().norm().transpose();
    for (Eigen::Index j = 0; j < scale.size(); ++j)
      if (!(scale(j) > 0)) scale(j) = 1;
    Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(base * scale.cwiseInverse().asDiagonal());
    qr.setThreshold(1e-12);
    q_ = qr.householderQ() * Eigen::MatrixXd::Identity(d.rows, qr.rank());
    y_hat_ = y - q_ * (q_.transpose() * y);
    yy_ = y_hat_.squaredNorm();
  }

  Projected Column(double tau) const {
    Projected c;
    c.tau = tau;
    c.g.resize(d_.rows);
    Eigen::Index at = 0;
    for (const auto& t : d_.t)
      for (const double v : t) c.g(at++) = 1.0 - std::exp(-v / tau);
    c.raw = c.g.squaredNorm();
    c.g -= q_ * (q_.transpose() * c.g);
    c.gg = c.g.squaredNorm();
    c.gy = c.g.dot(y_hat_);
    return c;
  }

  // A column the rest of the design explains (|g_hat| below 1e-12 of |g|: the rank threshold).
  static bool Degenerate(const Projected& c) { return !(c.gg > 1e-24 * c.raw); }

  // Residual sum of squares and gains of one term.
  double One(const Projected& a, double* gain) const {
    *gain = Degenerate(a) ? 0.0 : a.gy / a.gg;
    return std::max(yy_ - *gain * a.gy, 0.0);
  }

  // Residual sum of squares and gains of two terms, the gains held to one sign (FitWarmUp): with
  // opposite signs, the better of each term alone (the other gain 0). `ab` = g_hat_a' g_hat_b.
  double Two(const Projected& a, const Projected& b, double ab, double* ga, double* gb) const {
    const double det = a.gg * b.gg - ab * ab;
    if (!Degenerate(a) && !Degenerate(b) && det > 1e-12 * a.gg * b.gg) {
      *ga = (b.gg * a.gy - ab * b.gy) / det;
      *gb = (a.gg * b.gy - ab * a.gy) / det;
      if (*ga * *gb >= 0) return std::max(yy_ - *ga * a.gy - *gb * b.gy, 0.0);
    }
    double only_a = 0, only_b = 0;
    const double sa = One(a, &only_a), sb = One(b, &only_b);
    // The first term alone wins only when strictly better (on a tie, the second).
    if (sa < sb) {
      *ga = only_a, *gb = 0.0;
      return sa;
    }
    *ga = 0.0, *gb = only_b;
    return sb;
  }

  // The coefficients b0, the fixed columns', then the gains, for time constants `cols` with
  // gains `gains` (the fixed part by least squares on what the warm-up leaves).
  Eigen::VectorXd Coefficients(const std::vector<const Projected*>& cols,
                               const std::vector<double>& gains) const {
    Eigen::VectorXd rest = y_;
    for (std::size_t j = 0; j < cols.size(); ++j) {
      if (gains[j] == 0.0) continue;
      Eigen::Index at = 0;
      for (const auto& t : d_.t)
        for (const double v : t) rest(at++) -= gains[j] * (1.0 - std::exp(-v / cols[j]->tau));
    }
    const Eigen::VectorXd base = LeastSquaresCoefficients(d_.fixed.cols() > 0
                                                              ? d_.fixed
                                                              : Eigen::MatrixXd(d_.rows, 0),
                                                          rest);
    Eigen::VectorXd b(base.size() + static_cast<Eigen::Index>(cols.size()));
    b.head(base.size()) = base;
    for (std::size_t j = 0; j < cols.size(); ++j)
      b(base.size() + static_cast<Eigen::Index>(j)) = gains[j];
    return b;
  }

 private:
  const WarmUpData& d_;
  const Eigen::VectorXd& y_;
  Eigen::MatrixXd q_;  // orthonormal basis of span [1 fixed]
  Eigen::VectorXd y_hat_;
  double yy_ = 0;
};

Eigen::VectorXd WarmUpTarget(const WarmUpData& d) {
  Eigen::VectorXd y(d.rows);
  Eigen::Index at = 0;
  for (const auto& e : d.e) {
    y.segment(at, e.size()) = e;
    at += e.size();
  }
  return y;
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

std::vector<double> LogGrid(const WarmUpData& d, double sampling_step) {
  double step = sampling_step;
  if (!(step > 0)) {
    std::vector<double> steps;
    for (const auto& t : d.t)
      for (std::size_t k = 1; k < t.size(); ++k) steps.push_back(t[k] - t[k - 1]);
    std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2),
                     steps.end());
    step = steps[steps.size() / 2];
  }
  const double lo = 2 * step;
  const double hi = std::max(kMaxWarmUpTauPerSpan * LongestSpan(d), lo);
  std::vector<double> grid(41);
  for (int i = 0; i < 41; ++i) grid[static_cast<std::size_t>(i)] = lo * std::pow(hi / lo, i / 40.0);
  return grid;
}

// Best grid point (one term) or pair with tau_2 >= 3 tau_1 (two terms), as grid indices; `cols`
// receives the grid's projected columns.
std::vector<std::size_t> GridSearch(const WarmUpLeastSquares& ls, const std::vector<double>& grid,
                                    int terms, std::vector<Projected>* cols) {
  cols->clear();
  for (double tau : grid) cols->push_back(ls.Column(tau));
  double best = std::numeric_limits<double>::infinity();
  std::vector<std::size_t> at;
  if (terms == 1) {
    for (std::size_t i = 0; i < grid.size(); ++i) {
      double g = 0;
      const double sse = ls.One((*cols)[i], &g);
      if (sse < best) best = sse, at = {i};
    }
    return at;
  }
  Eigen::MatrixXd g(cols->front().g.size(), static_cast<Eigen::Index>(cols->size()));
  for (std::size_t i = 0; i < cols->size(); ++i) g.col(static_cast<Eigen::Index>(i)) = (*cols)[i].g;
  const Eigen::MatrixXd gram = g.transpose() * g;
  for (std::size_t i = 0; i < grid.size(); ++i)
    for (std::size_t k = i + 1; k < grid.size(); ++k) {
      if (grid[k] < 3 * grid[i]) continue;
      double a = 0, b = 0;
      const double sse = ls.Two((*cols)[i], (*cols)[k],
                                gram(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(k)),
                                &a, &b);
      if (sse < best) best = sse, at = {i, k};
    }
  return at;
}

// The residual sum of squares and gains for time constants `cols` (one or two).
double WarmUpSse(const WarmUpLeastSquares& ls, const std::vector<const Projected*>& cols,
                 std::vector<double>* gains) {
  gains->assign(cols.size(), 0.0);
  if (cols.size() == 1) return ls.One(*cols[0], &(*gains)[0]);
  return ls.Two(*cols[0], *cols[1], cols[0]->g.dot(cols[1]->g), &(*gains)[0], &(*gains)[1]);
}

}  // namespace

WarmUpFit FitWarmUp(const std::vector<std::vector<double>>& times,
                    const std::vector<Eigen::VectorXd>& errors, int terms,
                    const Eigen::MatrixXd& fixed, double sampling_step) {
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
  const WarmUpLeastSquares ls(d, y);
  const std::vector<double> grid = LogGrid(d, sampling_step);
  std::vector<Projected> grid_cols;
  const std::vector<std::size_t> at = GridSearch(ls, grid, terms, &grid_cols);
  if (at.empty()) {  // two terms 3 apart do not fit between two sample steps and the span
    WarmUpFit one = FitWarmUp(times, errors, 1, fixed, sampling_step);
    one.note = "the trained span is too short for two time constants: one term" +
               std::string(one.note.empty() ? "" : "; ") + one.note;
    return one;
  }
  std::vector<Projected> cols;
  for (std::size_t i : at) cols.push_back(grid_cols[i]);
  grid_cols.clear();
  std::vector<double> gains;
  for (std::size_t j = 0; j < cols.size(); ++j) {  // refine each tau between its neighbours
    const std::size_t i = at[j];
    const double lo = grid[i > 0 ? i - 1 : 0], hi = grid[std::min(i + 1, grid.size() - 1)];
    const double lower = j == 1 ? std::max(lo, 3 * cols[0].tau) : lo;
    const double upper = j == 0 && cols.size() == 2 ? std::min(hi, cols[1].tau / 3) : hi;
    if (!(upper > lower)) continue;
    std::vector<const Projected*> trial;
    for (const Projected& c : cols) trial.push_back(&c);
    Projected moving;
    const double tau = GoldenLog(
        [&](double v) {
          moving = ls.Column(v);
          trial[j] = &moving;
          return WarmUpSse(ls, trial, &gains);
        },
        lower, upper);
    cols[j] = ls.Column(tau);
  }
  std::vector<const Projected*> chosen;
  for (const Projected& c : cols) chosen.push_back(&c);
  WarmUpFit f;
  f.span = LongestSpan(d);
  f.rmse_um = std::sqrt(WarmUpSse(ls, chosen, &gains) / static_cast<double>(d.rows));
  std::vector<double> taus;
  for (const Projected& c : cols) taus.push_back(c.tau);
  std::vector<std::size_t> kept_at = at;
  if (taus.size() == 2 && (gains[0] == 0.0 || gains[1] == 0.0)) {
    const std::size_t zero = gains[0] == 0.0 ? 0 : 1;  // the term held at 0: dropped
    taus.erase(taus.begin() + static_cast<std::ptrdiff_t>(zero));
    kept_at.erase(kept_at.begin() + static_cast<std::ptrdiff_t>(zero));
    chosen.erase(chosen.begin() + static_cast<std::ptrdiff_t>(zero));
    gains.erase(gains.begin() + static_cast<std::ptrdiff_t>(zero));
    f.note = "two terms would need gains of opposite sign: one term kept";
  }
  f.coefficients = ls.Coefficients(chosen, gains);
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
