#include "sim/features.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"

namespace whirl::sim {
namespace {

double Median(std::vector<double> v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  double m = v[mid];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + mid));
  return m;
}

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
  if (o.tail_degree < 0 || o.tail_degree > 2) fail("tail_degree", o.tail_degree, "0, 1 or 2");
  if (!(o.noise_sigma_multiplier >= 0))
    fail("noise_sigma_multiplier", o.noise_sigma_multiplier, "must be >= 0");
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

  // 1. Centred moving average (two pointers over prefix sums).
  std::vector<double> prefix(n + 1, 0.0);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + y[i];
  std::vector<double> smooth(n);
  std::vector<double> window_count(n);
  const double half = 0.5 * options.smoothing_window_s;
  std::size_t lo = 0, hi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (t[lo] < t[i] - half) ++lo;
    if (hi < i) hi = i;
    while (hi + 1 < n && t[hi + 1] <= t[i] + half) ++hi;
    const double count = static_cast<double>(hi - lo + 1);
    smooth[i] = (prefix[hi + 1] - prefix[lo]) / count;
    window_count[i] = count;
  }

  // 2. Tail line by least squares on the raw samples.
  const double t_tail = t.back() - options.tail_fraction * (t.back() - t.front());
  std::size_t tail_begin = 0;
  while (tail_begin < n && t[tail_begin] < t_tail) ++tail_begin;
  tail_begin = std::min(tail_begin, n - 3);
  const std::size_t m = n - tail_begin;
  // Polynomial in the scaled time u = (t - t_mid) / t_half for conditioning.
  const double t_mid = 0.5 * (t[tail_begin] + t.back());
  const double t_half = std::max(1e-12, 0.5 * (t.back() - t[tail_begin]));
  const int degree = options.tail_degree;
  Eigen::MatrixXd design(m, degree + 1);
  Eigen::VectorXd rhs(m);
  for (std::size_t i = 0; i < m; ++i) {
    const double u = (t[tail_begin + i] - t_mid) / t_half;
    double p = 1.0;
    for (int d = 0; d <= degree; ++d, p *= u) design(static_cast<Eigen::Index>(i), d) = p;
    rhs(static_cast<Eigen::Index>(i)) = y[tail_begin + i];
  }
  const Eigen::VectorXd coef = design.colPivHouseholderQr().solve(rhs);
  auto plateau = [&](double tt) {
    const double u = (tt - t_mid) / t_half;
    double v = 0.0, p = 1.0;
    for (int d = 0; d <= degree; ++d, p *= u) v += coef(d) * p;
    return v;
  };
  const double slope = (plateau(t.back()) - plateau(t[tail_begin])) / (2.0 * t_half);

  // 3. Robust noise level of the raw tail.
  std::vector<double> resid;
  resid.reserve(m);
  for (std::size_t i = tail_begin; i < n; ++i) resid.push_back(y[i] - plateau(t[i]));
  const double med = Median(resid);
  for (double& r : resid) r = std::abs(r - med);
  const double sigma = 1.4826 * Median(resid);
  std::vector<double> counts(window_count.begin() + static_cast<std::ptrdiff_t>(tail_begin),
                             window_count.end());
  const double n_win = std::max(1.0, Median(counts));
  const double noise_floor = options.noise_sigma_multiplier * sigma / std::sqrt(n_win);

  // 4./5. Last excursion of the smoothed curve outside the band.
  auto band = [&](double tt) {
    return std::max(options.tolerance_rel * std::abs(plateau(tt)), noise_floor);
  };
  std::size_t settle_index = 0;
  for (std::size_t i = n; i-- > 0;) {
    if (std::abs(smooth[i] - plateau(t[i])) > band(t[i])) {
      settle_index = std::min(i + 1, n - 1);
      break;
    }
  }
  SettleAnalysis a;
  a.features.settle_time_s = t[settle_index] - t.front();
  a.features.max_elongation_um = plateau(t[settle_index]);
  a.plateau_slope_um_per_s = slope;
  a.noise_std_um = sigma;
  a.band_um = band(t[settle_index]);
  a.settled_before_tail = t[settle_index] < t_tail;
  std::ostringstream msg;
  msg << "plateau " << FormatNumber(a.features.max_elongation_um) << " um (tail fit from "
      << FormatNumber(t_tail) << " s, slope " << FormatNumber(slope * 3600.0)
      << " um/h mean), band +-" << FormatNumber(a.band_um) << " um = max(" << options.tolerance_rel
      << " x plateau, " << options.noise_sigma_multiplier << " x noise " << FormatNumber(sigma)
      << " um / sqrt(" << FormatNumber(n_win) << ")); smoothed curve stays in the band from "
      << FormatNumber(a.features.settle_time_s) << " s"
      << (a.settled_before_tail ? "" : " (NOT before the tail window: record too short)");
  a.message = msg.str();
  return a;
}

Features ExtractFeatures(const ElongationCurve& curve, const SettleOptions& options) {
  return AnalyzeSettle(curve, options).features;
}

}  // namespace whirl::sim
