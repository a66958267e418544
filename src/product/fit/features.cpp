#include "fit/features.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"
#include "core/stats.h"

namespace whirl::fit {
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
  if (!(o.min_window_s > 0)) fail("min_window_s", o.min_window_s, "must be > 0");
  if (!(o.window_growth > 1)) fail("window_growth", o.window_growth, "must be > 1");
  if (!(o.window_to_settle_ratio >= 1))
    fail("window_to_settle_ratio", o.window_to_settle_ratio, "must be >= 1");
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

namespace {

void CheckFeatureCurve(const ElongationCurve& curve) {
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
}

// Centred moving-average windows [lo[i], hi[i]] of width `width_s` over the times t (two
// pointers).
struct MovingWindows {
  std::vector<std::size_t> lo, hi;
  MovingWindows(const std::vector<double>& t, double width_s) : lo(t.size()), hi(t.size()) {
    const std::size_t n = t.size();
    const double half = 0.5 * width_s;
    for (std::size_t i = 0, l = 0, h = 0; i < n; ++i) {
      while (t[l] < t[i] - half) ++l;
      if (h < i) h = i;
      while (h + 1 < n && t[h + 1] <= t[i] + half) ++h;
      lo[i] = l;
      hi[i] = h;
    }
  }
  double Count(std::size_t i) const { return static_cast<double>(hi[i] - lo[i] + 1); }
};

// Where the detrended curve y - drift, smoothed over the windows, last leaves the band around
// the plateau: the settle index is the sample after the last one outside (0 if none is), with
// the band's half width there, um.
struct BandExit {
  std::size_t settle_index = 0;
  double band_um = 0;
};
BandExit LastBandExit(const std::vector<double>& u, const std::vector<double>& y,
                      const DriftFit& fit, const MovingWindows& w, const SettleOptions& options) {
  const std::size_t n = y.size();
  const double plateau = fit.coef(0);
  std::vector<double> prefix(n + 1), smooth(n);
  for (std::size_t i = 0; i < n; ++i) prefix[i + 1] = prefix[i] + (y[i] - fit.Drift(u[i]));
  for (std::size_t i = 0; i < n; ++i)
    smooth[i] = (prefix[w.hi[i] + 1] - prefix[w.lo[i]]) / w.Count(i);
  auto band = [&](std::size_t i) {
    return std::max(options.tolerance_rel * std::abs(plateau),
                    options.noise_sigma_multiplier * fit.sigma / std::sqrt(w.Count(i)));
  };
  BandExit exit;
  for (std::size_t i = n; i-- > 0;) {
    if (std::abs(smooth[i] - plateau) > band(i)) {
      exit.settle_index = std::min(i + 1, n - 1);
      break;
    }
  }
  exit.band_um = band(exit.settle_index);
  return exit;
}

// SettleAnalysis::message: the plateau, the fit and the band that decided the settle time.
std::string DescribeSettle(const SettleAnalysis& a, const SettleOptions& options) {
  std::ostringstream msg;
  msg << "plateau " << MessageNumber(a.features.max_elongation_um)
      << " um at the settle time (fit of"
      << " plateau + degree-" << options.drift_degree << " drift from "
      << MessageNumber(a.fit_start_s) << " s, " << a.iterations << " passes; drift "
      << MessageNumber(a.drift_at_settle_um) << " um at the settle time, "
      << MessageNumber(a.drift_at_end_um) << " um at the end), band +-" << MessageNumber(a.band_um)
      << " um = max(" << options.tolerance_rel << " x plateau, " << options.noise_sigma_multiplier
      << " x noise " << MessageNumber(a.noise_std_um) << " um / sqrt(samples in "
      << options.smoothing_window_s << " s)); detrended smoothed curve stays in the band from "
      << MessageNumber(a.features.settle_time_s) << " s"
      << (a.settled_before_tail ? "" : " (NOT before the tail window: record too short)");
  return msg.str();
}

// Steps 1-6 of the header on the whole of `curve`.
SettleAnalysis AnalyzeRecord(const ElongationCurve& curve, const SettleOptions& options) {
  const std::size_t n = curve.size();
  const std::vector<double>& t = curve.time_s;
  const std::vector<double>& y = curve.elongation_um;
  const double t0 = t.front(), span = t.back() - t.front();
  std::vector<double> u(n);
  for (std::size_t i = 0; i < n; ++i) u[i] = (t[i] - t0) / span;
  auto index_at = [&](double tt) {
    std::size_t i = static_cast<std::size_t>(std::lower_bound(t.begin(), t.end(), tt) - t.begin());
    return std::min(i, n - 3);
  };
  const MovingWindows windows(t, options.smoothing_window_s);

  const double t_tail = t0 + (1.0 - options.tail_fraction) * span;
  const std::size_t tail_begin = index_at(t_tail);
  std::size_t fit_begin = tail_begin;
  int degree = std::min(1, options.drift_degree);
  DriftFit fit;
  BandExit settle;
  int iterations = 0;
  std::vector<std::size_t> visited;
  for (int pass = 0; pass < options.max_iterations; ++pass) {
    ++iterations;
    fit = FitPlateauAndDrift(u, y, fit_begin, degree);
    settle = LastBandExit(u, y, fit, windows, options);
    const std::size_t next_begin = std::min(
        tail_begin, index_at(t0 + options.fit_start_factor * (t[settle.settle_index] - t0)));
    // Stop at a fixed point, or when the window start comes back to an earlier value (a cycle
    // of two windows one sample apart: either answer is as good).
    const bool converged = degree == options.drift_degree &&
                           std::find(visited.begin(), visited.end(), next_begin) != visited.end();
    if (converged) break;
    if (degree == options.drift_degree) visited.push_back(fit_begin);
    fit_begin = next_begin;
    degree = options.drift_degree;
  }

  SettleAnalysis a;
  const std::size_t settle_index = settle.settle_index;
  const double ts = t[settle_index];
  a.features.settle_time_s = ts - t0;
  // The level where the plateau is reached, P + d(t_s): the fit determines it from samples just
  // after t_s, whereas P alone is a quadratic extrapolated back to t0 (several times noisier).
  a.features.max_elongation_um = fit.coef(0) + fit.Drift(u[settle_index]);
  a.drift_at_settle_um = fit.Drift(u[settle_index]);
  a.drift_at_end_um = fit.Drift(1.0);
  a.plateau_slope_um_per_s = (fit.Drift(1.0) - fit.Drift(u[fit_begin])) / (t.back() - t[fit_begin]);
  a.noise_std_um = fit.sigma;
  a.band_um = settle.band_um;
  a.fit_start_s = t[fit_begin];
  a.iterations = iterations;
  a.settled_before_tail = ts < t_tail;
  a.message = DescribeSettle(a, options);
  return a;
}

// Step S: transient shape + drift, y = L f(t; t_s) + c2 u^2 + c3 u^3, fitted to the whole record
// (u = (t - t0) / span). For a fixed t_s the model is linear in (L, c2, c3).
struct ShapeFit {
  double settle_s = 0, plateau = 0, c2 = 0, c3 = 0, rms = 0;
  double Drift(double u) const { return u * u * (c2 + c3 * u); }
};

double Shape(double t, double settle_s, const SettleOptions& o) {
  if (t >= settle_s) return 1.0;
  if (t <= 0) return 0.0;
  return std::atan(o.shape_k * std::pow(t / settle_s, o.time_exponent)) / std::atan(o.shape_k);
}

ShapeFit FitShapeAt(const ElongationCurve& c, double settle_s, const SettleOptions& o) {
  const double t0 = c.time_s.front(), span = c.time_s.back() - t0;
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d aty = Eigen::Vector3d::Zero();
  double yy = 0;
  for (std::size_t i = 0; i < c.size(); ++i) {
    const double u = (c.time_s[i] - t0) / span;
    const Eigen::Vector3d a(Shape(c.time_s[i] - t0, settle_s, o), u * u, u * u * u);
    ata += a * a.transpose();
    aty += a * c.elongation_um[i];
    yy += c.elongation_um[i] * c.elongation_um[i];
  }
  const Eigen::Vector3d x = ata.ldlt().solve(aty);
  ShapeFit f;
  f.settle_s = settle_s;
  f.plateau = x(0);
  f.c2 = x(1);
  f.c3 = x(2);
  const double sse = std::max(0.0, yy - 2 * x.dot(aty) + x.dot(ata * x));
  f.rms = std::sqrt(sse / static_cast<double>(c.size()));
  return f;
}

// Least squares over t_s: a log-spaced grid over (span / 500, span], then golden-section search
// between the neighbours of the best grid point.
ShapeFit FitShape(const ElongationCurve& c, const SettleOptions& o) {
  const double span = c.time_s.back() - c.time_s.front();
  const double lo = std::log(span / 500.0), hi = std::log(span);
  constexpr int kGrid = 80;
  ShapeFit best;
  int best_k = 0;
  for (int k = 0; k <= kGrid; ++k) {
    const ShapeFit f = FitShapeAt(c, std::exp(lo + (hi - lo) * k / kGrid), o);
    if (k == 0 || f.rms < best.rms) best = f, best_k = k;
  }
  double a = lo + (hi - lo) * std::max(0, best_k - 1) / kGrid;
  double b = lo + (hi - lo) * std::min(kGrid, best_k + 1) / kGrid;
  const double g = 0.5 * (std::sqrt(5.0) - 1.0);
  for (int it = 0; it < 40; ++it) {
    const double x1 = b - g * (b - a), x2 = a + g * (b - a);
    const ShapeFit f1 = FitShapeAt(c, std::exp(x1), o), f2 = FitShapeAt(c, std::exp(x2), o);
    if (f1.rms < f2.rms)
      b = x2;
    else
      a = x1;
    if (f1.rms < best.rms) best = f1;
    if (f2.rms < best.rms) best = f2;
  }
  return best;
}

SettleAnalysis AnalyzeByShape(const ElongationCurve& c, const SettleOptions& o) {
  const ShapeFit f = FitShape(c, o);
  const double t0 = c.time_s.front(), span = c.time_s.back() - t0;
  SettleAnalysis a;
  const double u_s = f.settle_s / span;
  a.features.settle_time_s = f.settle_s;
  a.features.max_elongation_um = f.plateau;
  a.drift_at_settle_um = f.Drift(u_s);
  a.drift_at_end_um = f.Drift(1.0);
  a.plateau_slope_um_per_s = (f.Drift(1.0) - f.Drift(u_s)) / std::max(1e-9, span - f.settle_s);
  a.noise_std_um = f.rms;
  a.fit_start_s = t0;
  a.iterations = 1;
  a.settled_before_tail = f.settle_s < (1.0 - o.tail_fraction) * span;
  std::ostringstream msg;
  msg << "least-squares fit over " << MessageNumber(span) << " s of L atan(" << o.shape_k
      << " (t/t_s)^" << o.time_exponent << ")/atan(" << o.shape_k
      << ") + drift c2 u^2 + c3 u^3: L = " << MessageNumber(f.plateau)
      << " um, t_s = " << MessageNumber(f.settle_s) << " s, drift "
      << MessageNumber(a.drift_at_settle_um) << " um at t_s, " << MessageNumber(a.drift_at_end_um)
      << " um at the end, residual rms " << MessageNumber(f.rms) << " um"
      << (a.settled_before_tail ? "" : " (t_s NOT before the last part of the record: too short)");
  a.message = msg.str();
  return a;
}

SettleAnalysis AnalyzeWindow(const ElongationCurve& c, const SettleOptions& o) {
  return o.method == SettleMethod::kShapeFit ? AnalyzeByShape(c, o) : AnalyzeRecord(c, o);
}

// The first samples of `curve` up to time t0 + window_s.
ElongationCurve Head(const ElongationCurve& curve, double window_s) {
  ElongationCurve h;
  const double t_end = curve.time_s.front() + window_s;
  for (std::size_t i = 0; i < curve.size() && curve.time_s[i] <= t_end; ++i) {
    h.time_s.push_back(curve.time_s[i]);
    h.elongation_um.push_back(curve.elongation_um[i]);
  }
  return h;
}

}  // namespace

SettleAnalysis AnalyzeSettle(const ElongationCurve& curve, const SettleOptions& options) {
  CheckOptions(options);
  CheckFeatureCurve(curve);
  const double record_s = curve.time_s.back() - curve.time_s.front();
  int windows = 0;
  for (double w = options.min_window_s; w < record_s; w *= options.window_growth) {
    const ElongationCurve head = Head(curve, w);
    if (head.size() < 10) continue;
    ++windows;
    SettleAnalysis a = AnalyzeWindow(head, options);
    if (a.features.settle_time_s * options.window_to_settle_ratio <= w) {
      a.windows = windows;
      a.window_s = w;
      return a;
    }
  }
  SettleAnalysis a = AnalyzeWindow(curve, options);
  a.windows = windows + 1;
  a.window_s = record_s;
  return a;
}

Features ExtractFeatures(const ElongationCurve& curve, const SettleOptions& options) {
  return AnalyzeSettle(curve, options).features;
}

}  // namespace whirl::fit
