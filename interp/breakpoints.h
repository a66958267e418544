#pragma once
// Compensation points: breakpoints on a curve l(t) such that the piecewise-linear interpolant
// through them (the compensation the control applies, Li, Ma and Jiang section 3:
// l_C = l_A + (t_C - t_A) tan(beta), tan(beta) = (l_B - l_A)/(t_B - t_A)) never leaves the curve
// by more than a tolerance, with as few points as possible: dense while the curve moves, sparse on
// its plateau.
//
// Algorithm (greedy chords on a dense grid):
//   1. The interval [t_begin, t_end] is sampled on a uniform check grid of step h <= check_step_s,
//      and forced times (e.g. the settle time, where the arctan curve has a kink) are inserted.
//   2. Effective tolerance tol_eff = tolerance_um - margin, margin = h^2/8 * max|l''| with l''
//      estimated from second differences of the grid (the error of a chord between two grid samples
//      can exceed its value at the samples by at most h^2 max|l''|/8). So the bound holds between
//      the samples too, for curves whose curvature the grid resolves. The first interval of the
//      grid is treated apart, because a curve may start with an infinite slope (the arctan curve
//      with time exponent p < 1): there a bound that needs no curvature is used,
//      h_i |s_i - s_{i+1}| (s_i the slope of grid chord i), valid when the curve is concave or
//      convex over the two intervals, and the first interval is subdivided towards t_begin until
//      that bound is no larger than the rest of the grid's margin (or 5 % of the tolerance).
//   3. From breakpoint A (a grid sample), B is pushed as far as possible while the chord A-B stays
//      within tol_eff of every grid sample between them: doubling then bisection over the grid
//      index (a forced time is never skipped). The found B becomes the next A.
//   Breakpoints lie ON the curve, so the compensation passes through the predicted values.
//   Optimality: with chords constrained to pass through curve samples, greedy-farthest is optimal
//   (fewest points) when "chord A-B is within tolerance" is monotone in B for each A and the
//   segments are interval-nested (true for concave or convex stretches such as the arctan curve);
//   the bisection relies on the same monotonicity. The tolerance bound itself never relies on it:
//   every emitted chord is checked on all grid samples it spans.
//   Cost: O(G log G) curve evaluations, G = grid size.
#include <functional>
#include <vector>

namespace whirl::interp {

/// The curve to follow: elongation in um at time t_s (s from the start of the cut).
using CurveFunction = std::function<double(double t_s)>;

struct BreakpointOptions {
  /// Largest allowed |piecewise-linear interpolant - curve|, um (> 0). Default from the issue.
  double tolerance_um = 0.5;
  /// Largest check-grid step, s (> 0). The grid starts with ceil((t_end - t_begin)/check_step_s)
  /// steps and is refined (step halved) until the curvature margin is below tolerance_um / 2.
  double check_step_s = 0.25;
  /// Guard against absurd grids: more samples than this is an InputError (raise check_step_s).
  std::size_t max_grid_samples = 20'000'000;
  /// Interior times that must be breakpoints (kinks of the curve), s. Outside (t_begin, t_end):
  /// ignored.
  std::vector<double> forced_times_s;
};

struct Breakpoints {
  std::vector<double> time_s;         ///< strictly increasing; first = t_begin, last = t_end
  std::vector<double> value_um;       ///< curve value at each breakpoint, um
  double tolerance_um = 0;            ///< requested bound
  double effective_tolerance_um = 0;  ///< tolerance_um minus the curvature margin (step 2)
  double max_deviation_um = 0;        ///< largest |interpolant - curve| over the check grid, um
  double check_step_s = 0;            ///< grid step actually used, s
  std::size_t grid_samples = 0;

  std::size_t size() const { return time_s.size(); }
  /// Piecewise-linear interpolant at t (clamped to the end values outside the range), um.
  double InterpolateUm(double t_s) const;
};

/// Chooses breakpoints on [t_begin_s, t_end_s] (see the algorithm above). Throws InputError for
/// t_end <= t_begin, non-finite bounds, tolerance_um <= 0 or non-finite, check_step_s <= 0, a grid
/// above max_grid_samples (also when refining it for a tiny tolerance), or a non-finite curve value
/// (naming the time).
Breakpoints ChooseBreakpoints(const CurveFunction& curve, double t_begin_s, double t_end_s,
                              const BreakpointOptions& options = {});

/// Smallest number N >= 2 of uniformly spaced points on [t_begin, t_end] (including both ends,
/// points on the curve) whose piecewise-linear interpolant stays within the same effective
/// tolerance on the same check grid (forced times are not given to the uniform rule). Found by
/// doubling then bisection on N, then verified; returns 0 when even `max_points` points do not
/// reach the bound.
std::size_t UniformPointCount(const CurveFunction& curve, double t_begin_s, double t_end_s,
                              const BreakpointOptions& options = {},
                              std::size_t max_points = 1'000'000);

/// Largest |interpolant through (t, value) - curve| over a uniform grid of step <= check_step_s on
/// [t.front(), t.back()] plus the breakpoints, um. For tests and reports.
double MaxInterpolationErrorUm(const CurveFunction& curve, const std::vector<double>& time_s,
                               const std::vector<double>& value_um, double check_step_s);

}  // namespace whirl::interp
