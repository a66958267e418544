#include "sim/features.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"
#include "core/stats.h"

namespace whirl::sim {
namespace {

void CheckOptions(const SettleOptions& o) {
  auto fail = [](const char* field, double value, const char* rule) {
    throw InputError(std::string("settle options: ") + field + " = " + FormatNumber(value) +
                     " breaks the rule: " + rule);
  };
  if (!(o.tolerance_rel > 0 && o.tolerance_rel < 1))
    fail("tolerance_rel", o.tolerance_rel, "0 < x < 1");
  if (!(o.smoothing_window_s >= 0))
    fail("smoothing_window_s", o.smoothing_window_s, "must be >= 0");
  if (!(o.tail_fraction > 0 && o.tail_fraction < 1))
    fail("tail_fraction", o.tail_fraction, "0 < x < 1");
  if (o.drift_degree < 0 || o.drift_degree > 3) fail("drift_degree", o.drift_degree, "0 to 3");
  if (!(o.noise_sigma_multiplier >= 0))
    fail("noise_sigma_multiplier", o.noise_sigma_multiplier, "must be >= 0");
  if (!(o.fit_start_factor >= 1)) fail("fit_start_factor", o.fit_start_factor, "must be >= 1");
  if (o.max_iterations < 1) fail("max_iterations", o.max_iterations, "must be >= 1");
}

// Plateau + drift fitted to samples [begin, n): coef(0) = P, coef(k) = c_k of u^k.
struct DriftFit {
  Eigen::VectorXd coef;
  double sigma = 0;
  double Drift(double u) const {
    double v = 0.0, p = u;
    for (Eigen::Index k = 1; k < coef.size(); ++k, p *= u) v += coef(k) * p;
    return v;
  }
};

DriftFit FitPlateauAndDrift(const std::vector<double>& u, const std::vector<double>& y,
                            std::size_t begin, int degree) {
  const std::size_t n = u.size(), m = n - begin;
  Eigen::MatrixXd design(m, degree + 1);
  Eigen::VectorXd rhs(m), w = Eigen::VectorXd::Ones(m);
  for (std::size_t i = 0; i < m; ++i) {
    double p = 1.0;
    for (int d = 0; d <= degree; ++d, p *= u[begin + i])
      design(static_cast<Eigen::Index>(i), d) = p;
    rhs(static_cast<Eigen::Index>(i)) = y[begin + i];
  }
  DriftFit f;
  std::vector<double> resid(m);
  // Huber IRLS: Gaussian noise gives plain least squares; spikes of a real sensor lose weight.
  for (int pass = 0; pass < 4; ++pass) {
    const Eigen::MatrixXd wd = w.asDiagonal() * design;
    f.coef = wd.colPivHouseholderQr().solve(w.asDiagonal() * rhs);
    const Eigen::VectorXd r = rhs - design * f.coef;
    for (std::size_t i = 0; i < m; ++i) resid[i] = r(static_cast<Eigen::Index>(i));
    const double med = Median(resid);
    std::vector<double> dev(m);
    for (std::size_t i = 0; i < m; ++i) dev[i] = std::abs(resid[i] - med);
    f.sigma = 1.4826 * Median(dev);
    const double c = 1.345 * f.sigma;
    for (std::size_t i = 0; i < m; ++i) {
      const double a = std::abs(resid[i]);
      w(static_cast<Eigen::Index>(i)) = (c > 0 && a > c) ? std::sqrt(c / a) : 1.0;
    }
  }
  return f;
}

}  // namespace

SettleAnalysis AnalyzeSettle(const ElongationCurve& curve, const SettleOptions& options) {
  CheckOptions(options);
  const std::size_t n = curve.size();
  if (n < 10 || curve.elongation_um.size() != n)
    throw InputError("elongation curve: " + std::to_string(n) +
                     " samples breaks the rule: at least 10 samples with matching columns are "
                     "needed to extract features");
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(curve.time_s[i]) || !std::isfinite(curve.elongation_um[i]))
      throw InputError("elongation curve: sample " + std::to_string(i + 1) +
                       " is not finite (time_s = " + FormatNumber(curve.time_s[i]) +
                       ", elongation_um = " + FormatNumber(curve.elongation_um[i]) + ")");
    if (i > 0 && !(curve.time_s[i] > curve.time_s[i - 1]))
      throw InputError("elongation curve: time_s = " + FormatNumber(curve.time_s[i]) +
                       " at sample " + std::to_string(i + 1) +
                       " breaks the rule: time must increase strictly");
  }
  const std::vector<double>& t = curve.time_s;
  const std::vector<double>& y = curve.elongation_um;
  const double t0 = t.front(), span = t.back() - t.front();
  std::vector<double> u(n);
  for (std::size_t i = 0; i < n; ++i) u[i] = (t[i] - t0) / span;
  auto index_at = [&](double tt) {
    std::size_t i = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), tt) - t.begin());
    return std::min(i, n - 3);
  };

  // Centred moving-average windows [lo_i, hi_i] (two pointers); counts n_i.
  std::vector<std::size_t> win_lo(n), win_hi(n);
  const double half = 0.5 * options.smoothing_window_s;
  for (std::size_t i = 0, lo = 0, hi = 0; i < n; ++i) {
    while (t[lo] < t[i] - half) ++lo;
    if (hi < i) hi = i;
    while (hi + 1 < n && t[hi + 1] <= t[i] + half) ++hi;
    win_lo[i] = lo;
    win_hi[i] = hi;
  }
  std::vector<double> prefix(n + 1), smooth(n);

  const double t_tail = t0 + (1.0 - options.tail_fraction) * span;
  const std::size_t tail_begin = index_at(t_tail);
  std::size_t fit_begin = tail_begin;
  int degree = std::min(1, options.drift_degree);
  DriftFit fit;
  std::size_t settle_index = 0;
  double band_at_settle = 0;
  int iterations = 0;
  std::vector<std::size_t> visited;
  for (int pass = 0; pass < options.max_iterations; ++pass) {
    ++iterations;
    fit = FitPlateauAndDrift(u, y, fit_begin, degree);
    const double plateau = fit.coef(0);
    for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + (y[i] - fit.Drift(u[i]));
    for (std::size_t i = 0; i < n; ++i)
      smooth[i] = (prefix[win_hi[i] + 1] - prefix[win_lo[i]]) /
                  static_cast<double>(win_hi[i] - win_lo[i] + 1);
    auto band = [&](std::size_t i) {
      const double count = static_cast<double>(win_hi[i] - win_lo[i] + 1);
      return std::max(options.tolerance_rel * std::abs(plateau),
                      options.noise_sigma_multiplier * fit.sigma / std::sqrt(count));
    };
    std::size_t s = 0;
    for (std::size_t i = n; i-- > 0;) {
      if (std::abs(smooth[i] - plateau) > band(i)) {
        s = std::min(i + 1, n - 1);
        break;
      }
    }
    band_at_settle = band(s);
    const std::size_t next_begin =
        std::min(tail_begin, index_at(t0 + options.fit_start_factor * (t[s] - t0)));
    // Stop at a fixed point, or when the window start comes back to an earlier value (a cycle
    // of two windows one sample apart: either answer is as good).
    const bool converged =
        degree == options.drift_degree &&
        std::find(visited.begin(), visited.end(), next_begin) != visited.end();
    settle_index = s;
    if (converged) break;
    if (degree == options.drift_degree) visited.push_back(fit_begin);
    fit_begin = next_begin;
    degree = options.drift_degree;
  }

  SettleAnalysis a;
  const double ts = t[settle_index];
  a.features.settle_time_s = ts - t0;
  // The level where the plateau is reached, P + d(t_s): the fit determines it from samples just
  // after t_s, whereas P alone is a quadratic extrapolated back to t0 (several times noisier).
  a.features.max_elongation_um = fit.coef(0) + fit.Drift(u[settle_index]);
  a.drift_at_settle_um = fit.Drift(u[settle_index]);
  a.drift_at_end_um = fit.Drift(1.0);
  a.plateau_slope_um_per_s = (fit.Drift(1.0) - fit.Drift(u[fit_begin])) / (t.back() - t[fit_begin]);
  a.noise_std_um = fit.sigma;
  a.band_um = band_at_settle;
  a.fit_start_s = t[fit_begin];
  a.iterations = iterations;
  a.settled_before_tail = ts < t_tail;
  std::ostringstream msg;
  msg << "plateau " << FormatNumber(a.features.max_elongation_um) << " um at the settle time (fit of"
      << " plateau + degree-" << options.drift_degree << " drift from " << FormatNumber(a.fit_start_s)
      << " s, " << iterations << " passes; drift " << FormatNumber(a.drift_at_settle_um)
      << " um at the settle time, " << FormatNumber(a.drift_at_end_um)
      << " um at the end), band +-" << FormatNumber(a.band_um) << " um = max("
      << options.tolerance_rel << " x plateau, " << options.noise_sigma_multiplier << " x noise "
      << FormatNumber(a.noise_std_um) << " um / sqrt(samples in " << options.smoothing_window_s
      << " s)); detrended smoothed curve stays in the band from "
      << FormatNumber(a.features.settle_time_s) << " s"
      << (a.settled_before_tail ? "" : " (NOT before the tail window: record too short)");
  a.message = msg.str();
  return a;
}

Features ExtractFeatures(const ElongationCurve& curve, const SettleOptions& options) {
  return AnalyzeSettle(curve, options).features;
}

}  // namespace whirl::sim
