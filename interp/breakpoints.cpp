#include "interp/breakpoints.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::interp {
namespace {

// The check grid: uniform samples plus forced times, with the curve evaluated once.
struct Grid {
  std::vector<double> t;
  std::vector<double> l;
  std::vector<char> forced;
  double max_step = 0;
  double margin_um = 0;  // h^2/8 * 2 max|l''| (estimated) or the start's bound, see
                         // breakpoints.h step 2
};

void ValidateRange(double t_begin, double t_end, const BreakpointOptions& o) {
  if (!std::isfinite(t_begin) || !std::isfinite(t_end) || !(t_end > t_begin))
    throw InputError("breakpoints: time range [" + FormatSignificant(t_begin, 10) + ", " +
                     FormatSignificant(t_end, 10) + "] s: must be finite with end > begin");
  if (!std::isfinite(o.tolerance_um) || !(o.tolerance_um > 0))
    throw InputError("tolerance_um = " + FormatSignificant(o.tolerance_um, 10) +
                     ": must be a positive finite number");
  if (!std::isfinite(o.check_step_s) || !(o.check_step_s > 0))
    throw InputError("check_step_s = " + FormatSignificant(o.check_step_s, 10) +
                     ": must be a positive finite number");
}

Grid MakeGrid(const CurveFunction& curve, double t0, double t1, const BreakpointOptions& o) {
  ValidateRange(t0, t1, o);
  const double steps_real = std::ceil((t1 - t0) / o.check_step_s);
  if (!(steps_real + 1 <= static_cast<double>(o.max_grid_samples)))
    throw InputError("breakpoints: check grid of " + FormatSignificant(steps_real + 1, 10) +
                     " samples over " + FormatSignificant(t1 - t0, 10) +
                     " s exceeds max_grid_samples " + std::to_string(o.max_grid_samples) +
                     ": raise check_step_s");
  const auto steps = static_cast<std::size_t>(std::max(1.0, steps_real));
  const double h = (t1 - t0) / static_cast<double>(steps);
  std::vector<double> forced;
  for (double f : o.forced_times_s)
    if (std::isfinite(f) && f > t0 + 1e-9 * h && f < t1 - 1e-9 * h) forced.push_back(f);
  std::sort(forced.begin(), forced.end());
  // Uniform samples and forced times merged; a forced time within 1e-9 h of a sample replaces it.
  std::vector<std::pair<double, char>> samples;
  samples.reserve(steps + 1 + forced.size());
  for (std::size_t i = 0; i <= steps; ++i)
    samples.emplace_back(i == steps ? t1 : t0 + h * static_cast<double>(i), 0);
  for (double f : forced) samples.emplace_back(f, 1);
  std::sort(samples.begin(), samples.end());
  Grid g;
  for (const auto& [t, is_forced] : samples) {
    if (!g.t.empty() && t - g.t.back() <= 1e-9 * h) {
      if (is_forced) {
        g.t.back() = t;
        g.forced.back() = 1;
      }
      continue;
    }
    g.t.push_back(t);
    g.forced.push_back(is_forced);
  }
  g.l.resize(g.t.size());
  for (std::size_t i = 0; i < g.t.size(); ++i) {
    g.l[i] = curve(g.t[i]);
    if (!std::isfinite(g.l[i]))
      throw InputError("breakpoints: curve value at t = " + FormatSignificant(g.t[i], 10) +
                       " s is " + FormatSignificant(g.l[i], 10) + ": must be finite");
  }
  double max_curv = 0;
  for (std::size_t i = 0; i + 1 < g.t.size(); ++i)
    g.max_step = std::max(g.max_step, g.t[i + 1] - g.t[i]);
  for (std::size_t i = 1; i + 1 < g.t.size(); ++i) {
    if (g.forced[i]) continue;  // a kink is a breakpoint: no chord spans it
    const double ha = g.t[i] - g.t[i - 1], hb = g.t[i + 1] - g.t[i];
    const double second =
        2.0 * ((g.l[i + 1] - g.l[i]) / hb - (g.l[i] - g.l[i - 1]) / ha) / (ha + hb);
    max_curv = std::max(max_curv, std::abs(second));
  }
  // Twice the estimated curvature: a second difference averages l'' over two steps.
  g.margin_um = g.max_step * g.max_step / 8.0 * 2.0 * max_curv;
  return g;
}

// Bulge bound of grid interval i (between samples i and i + 1) that needs no curvature: if the
// curve is concave or convex over intervals i and i + 1, it lies between chord i and the line
// through sample i + 1 with the slope of chord i + 1, so it leaves chord i by at most
// h_i |s_i - s_{i+1}|. Without a usable next interval (the end, or a kink at sample i + 1) the
// bound of a monotone stretch, |l_{i+1} - l_i|.
double IntervalBound(const Grid& g, std::size_t i) {
  const double hi = g.t[i + 1] - g.t[i];
  const double si = (g.l[i + 1] - g.l[i]) / hi;
  if (i + 2 >= g.t.size() || g.forced[i + 1]) return std::abs(g.l[i + 1] - g.l[i]);
  const double sn = (g.l[i + 2] - g.l[i + 1]) / (g.t[i + 2] - g.t[i + 1]);
  return hi * std::abs(si - sn);
}

// The start of the curve. A curve may start with an unbounded slope and curvature (the arctan
// curve with p < 1 grows like t^p), where second differences underestimate the bulge of the first
// interval. Its bulge is bounded by IntervalBound instead; while that exceeds `target_um`, the
// worst interval of the start is halved (a fan of samples towards t_0, at most 200 of them).
// Returns the largest bound left on the start (the first uniform interval, now subdivided).
double RefineStart(const CurveFunction& curve, Grid* g, double target_um) {
  if (g->t.size() < 2) return 0.0;
  const double start_end = g->t[1];  // the first interval of the uniform grid
  std::size_t fan = 1;               // intervals 0 .. fan-1 lie in [t_0, start_end]
  for (int split = 0;; ++split) {
    std::size_t worst = 0;
    double worst_bound = -1;
    for (std::size_t i = 0; i < fan; ++i) {
      const double b = IntervalBound(*g, i);
      if (b > worst_bound) {
        worst_bound = b;
        worst = i;
      }
    }
    const double h = g->t[worst + 1] - g->t[worst];
    if (worst_bound <= target_um || split >= 200 || h <= 1e-12 * (start_end - g->t[0]))
      return worst_bound;
    const double tm = g->t[worst] + 0.5 * h;
    const double lm = curve(tm);
    if (!std::isfinite(lm))
      throw InputError("breakpoints: curve value at t = " + FormatSignificant(tm, 10) + " s is " +
                       FormatSignificant(lm, 10) + ": must be finite");
    g->t.insert(g->t.begin() + static_cast<std::ptrdiff_t>(worst) + 1, tm);
    g->l.insert(g->l.begin() + static_cast<std::ptrdiff_t>(worst) + 1, lm);
    g->forced.insert(g->forced.begin() + static_cast<std::ptrdiff_t>(worst) + 1, 0);
    ++fan;
  }
}

// The grid, refined (step halved) until the curvature margin is below half the tolerance.
Grid MakeRefinedGrid(const CurveFunction& curve, double t0, double t1, BreakpointOptions o,
                     double* effective_tolerance_um) {
  for (;;) {
    Grid g = MakeGrid(curve, t0, t1, o);
    // The start is refined until its bound is no worse than the rest of the grid's margin (or
    // 5 % of the tolerance, whichever is larger), so a steep start costs samples near t_0, not
    // tolerance everywhere.
    const double start_um = RefineStart(curve, &g, std::max(g.margin_um, 0.05 * o.tolerance_um));
    g.margin_um = std::max(g.margin_um, start_um);
    const double eff = o.tolerance_um - g.margin_um;
    if (eff > 0.5 * o.tolerance_um) {
      *effective_tolerance_um = eff;
      return g;
    }
    if (2.0 * static_cast<double>(g.t.size()) > static_cast<double>(o.max_grid_samples))
      throw InputError(
          "tolerance_um = " + FormatSignificant(o.tolerance_um, 10) +
          " um is too small for a check grid of at most " + std::to_string(o.max_grid_samples) +
          " samples: the margin between samples (curvature, or the bulge of a steep start) is " +
          FormatSignificant(g.margin_um, 10) + " um at step " + FormatSignificant(g.max_step, 10) +
          " s (must stay below half the tolerance)");
    o.check_step_s = 0.5 * g.max_step;
  }
}

// Is the chord from sample a to sample b within tol at every sample strictly between?
bool ChordFits(const Grid& g, std::size_t a, std::size_t b, double tol) {
  const double ta = g.t[a], la = g.l[a];
  const double slope = (g.l[b] - la) / (g.t[b] - ta);
  for (std::size_t i = a + 1; i < b; ++i)
    if (std::abs(la + slope * (g.t[i] - ta) - g.l[i]) > tol) return false;
  return true;
}

// Largest |interpolant - curve| over the grid samples, interpolant through (bt, bv).
double MaxErrorOnGrid(const Grid& g, const std::vector<double>& bt, const std::vector<double>& bv) {
  double worst = 0;
  std::size_t seg = 0;
  for (std::size_t i = 0; i < g.t.size(); ++i) {
    const double t = g.t[i];
    while (seg + 2 < bt.size() && t > bt[seg + 1]) ++seg;
    const double v = bv[seg] + (bv[seg + 1] - bv[seg]) * (t - bt[seg]) / (bt[seg + 1] - bt[seg]);
    worst = std::max(worst, std::abs(v - g.l[i]));
  }
  return worst;
}

bool UniformFits(const CurveFunction& curve, const Grid& g, std::size_t n, double tol,
                 std::vector<double>* bt, std::vector<double>* bv) {
  const double t0 = g.t.front(), t1 = g.t.back();
  bt->resize(n);
  bv->resize(n);
  for (std::size_t j = 0; j < n; ++j) {
    (*bt)[j] =
        j + 1 == n ? t1 : t0 + (t1 - t0) * static_cast<double>(j) / static_cast<double>(n - 1);
    (*bv)[j] = curve((*bt)[j]);
  }
  return MaxErrorOnGrid(g, *bt, *bv) <= tol;
}

}  // namespace

double Breakpoints::InterpolateUm(double t) const {
  if (time_s.empty()) return 0.0;
  if (t <= time_s.front()) return value_um.front();
  if (t >= time_s.back()) return value_um.back();
  const auto it = std::upper_bound(time_s.begin(), time_s.end(), t);
  const std::size_t b = static_cast<std::size_t>(it - time_s.begin());
  const std::size_t a = b - 1;
  return value_um[a] + (value_um[b] - value_um[a]) * (t - time_s[a]) / (time_s[b] - time_s[a]);
}

Breakpoints ChooseBreakpoints(const CurveFunction& curve, double t_begin_s, double t_end_s,
                              const BreakpointOptions& options) {
  double tol = 0;
  const Grid g = MakeRefinedGrid(curve, t_begin_s, t_end_s, options, &tol);
  const std::size_t last = g.t.size() - 1;
  Breakpoints bp;
  bp.tolerance_um = options.tolerance_um;
  bp.effective_tolerance_um = tol;
  bp.check_step_s = g.max_step;
  bp.grid_samples = g.t.size();
  bp.time_s.push_back(g.t[0]);
  bp.value_um.push_back(g.l[0]);
  std::size_t a = 0;
  while (a < last) {
    std::size_t limit = a + 1;  // the next forced sample (or the end): never skipped
    while (limit < last && !g.forced[limit]) ++limit;
    // Doubling: find ok <= fail with ChordFits(a, ok) and not ChordFits(a, fail) (or ok = limit).
    std::size_t ok = a + 1, step = 1;
    std::size_t fail = limit + 1;
    while (ok < limit) {
      step *= 2;
      const std::size_t b = std::min(a + step, limit);
      if (ChordFits(g, a, b, tol)) {
        ok = b;
      } else {
        fail = b;
        break;
      }
    }
    // Bisection between ok and fail.
    while (fail <= limit && fail - ok > 1) {
      const std::size_t mid = ok + (fail - ok) / 2;
      if (ChordFits(g, a, mid, tol))
        ok = mid;
      else
        fail = mid;
    }
    bp.time_s.push_back(g.t[ok]);
    bp.value_um.push_back(g.l[ok]);
    a = ok;
  }
  bp.max_deviation_um = MaxErrorOnGrid(g, bp.time_s, bp.value_um);
  return bp;
}

std::size_t UniformPointCount(const CurveFunction& curve, double t_begin_s, double t_end_s,
                              const BreakpointOptions& options, std::size_t max_points) {
  // The same grid and effective tolerance as ChooseBreakpoints; the forced times stay grid samples
  // (so no check interval spans a kink) but the uniform points ignore them.
  double tol = 0;
  const Grid g = MakeRefinedGrid(curve, t_begin_s, t_end_s, options, &tol);
  std::vector<double> bt, bv;
  std::size_t ok = 0, fail = 1;
  max_points = std::max<std::size_t>(max_points, 2);
  for (std::size_t n = 2;; n = std::min(2 * n, max_points)) {
    if (UniformFits(curve, g, n, tol, &bt, &bv)) {
      ok = n;
      break;
    }
    fail = n;
    if (n >= max_points) break;
  }
  if (ok == 0) return 0;
  while (ok - fail > 1) {
    const std::size_t mid = fail + (ok - fail) / 2;
    if (UniformFits(curve, g, mid, tol, &bt, &bv))
      ok = mid;
    else
      fail = mid;
  }
  return ok;
}

double MaxInterpolationErrorUm(const CurveFunction& curve, const std::vector<double>& time_s,
                               const std::vector<double>& value_um, double check_step_s) {
  if (time_s.size() < 2 || time_s.size() != value_um.size())
    throw InputError("interpolation error: need at least 2 points with one value each");
  BreakpointOptions o;
  o.check_step_s = check_step_s;
  o.forced_times_s.assign(time_s.begin() + 1, time_s.end() - 1);
  const Grid g = MakeGrid(curve, time_s.front(), time_s.back(), o);
  return MaxErrorOnGrid(g, time_s, value_um);
}

}  // namespace whirl::interp
