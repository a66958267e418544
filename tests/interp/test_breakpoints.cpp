// Breakpoints: the tolerance bound on many random curves at samples finer than the check grid,
// minimality against an exhaustive search, and the uniform-spacing count.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

#include "core/error.h"
#include "fit/arctan_curve.h"
#include "interp/breakpoints.h"

namespace whirl::interp {
namespace {

// Random curves over the whole admissible time-exponent range (the infinitely steep start
// of p < 1 is the hard case for the margin of the check grid), and p = 1 exactly.
fit::ArctanCurve RandomCurve(std::mt19937& rng) {
  std::uniform_real_distribution<double> ul(2.0, 150.0), uts(40.0, 800.0), uk(0.3, 15.0),
      up(0.5, 1.0);
  std::uniform_int_distribution<int> plain(0, 3);
  const double p = plain(rng) == 0 ? 1.0 : up(rng);
  return fit::ArctanCurve{ul(rng), uts(rng), uk(rng), p};
}

TEST(Breakpoints, BoundHoldsBetweenCheckSamplesOnRandomCurves) {
  std::mt19937 rng(21);
  std::uniform_real_distribution<double> utol(0.05, 3.0), ustep(0.1, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    const fit::ArctanCurve c = RandomCurve(rng);
    BreakpointOptions o;
    o.tolerance_um = utol(rng);
    o.check_step_s = ustep(rng);
    o.forced_times_s.assign(1, c.settle_time_s);
    const double t_end = c.settle_time_s * 3.0;
    auto f = [&](double t) { return c.ElongationUm(t); };
    const Breakpoints bp = ChooseBreakpoints(f, 0.0, t_end, o);
    ASSERT_GE(bp.size(), 2u);
    EXPECT_EQ(bp.time_s.front(), 0.0);
    EXPECT_EQ(bp.time_s.back(), t_end);
    double worst = 0;
    const int dense = 20000;  // ~7 to 200 samples per check step, off the grid
    for (int i = 0; i <= dense; ++i) {
      const double t = t_end * (i + 0.37) / dense;
      worst = std::max(worst, std::abs(bp.InterpolateUm(t) - f(t)));
    }
    EXPECT_LE(worst, o.tolerance_um)
        << "trial " << trial << " L " << c.max_elongation_um << " ts " << c.settle_time_s << " k "
        << c.shape_k << " p " << c.time_exponent;
    EXPECT_LE(bp.max_deviation_um, bp.effective_tolerance_um);
    for (std::size_t i = 0; i < bp.size(); ++i) EXPECT_DOUBLE_EQ(bp.value_um[i], f(bp.time_s[i]));
    // The settle time is a breakpoint and the plateau is a single flat segment to the end.
    ASSERT_GE(bp.size(), 3u);
    EXPECT_NEAR(bp.time_s[bp.size() - 2], c.settle_time_s, 1e-9 * c.settle_time_s);
    EXPECT_EQ(bp.value_um[bp.size() - 2], bp.value_um.back());
  }
}

TEST(Breakpoints, SteepStartStaysWithinTheBoundInsideTheFirstSegment) {
  // l = A t^p starts with an infinite slope and curvature: second differences underestimate the
  // bulge of the first check interval. The start is subdivided with a curvature-free bound, so the
  // tolerance holds everywhere inside the first (shortest) segments too, which a dense check of
  // the whole range would step over.
  for (double p : {0.5, 0.6, 0.75, 0.882}) {
    for (double a : {0.3, 2.0, 8.0}) {
      for (double tol : {0.05, 0.2, 0.5}) {
        auto f = [&](double t) { return t <= 0 ? 0.0 : a * std::pow(t, p); };
        BreakpointOptions o;
        o.tolerance_um = tol;
        o.check_step_s = 0.5;
        const double t_end = 400.0;
        const Breakpoints bp = ChooseBreakpoints(f, 0.0, t_end, o);
        double worst = 0;
        for (std::size_t seg = 0; seg + 1 < bp.size() && seg < 4; ++seg) {
          const double t0 = bp.time_s[seg], t1 = bp.time_s[seg + 1];
          for (int i = 1; i < 20000; ++i) {
            const double t = t0 + (t1 - t0) * i / 20000.0;
            worst = std::max(worst, std::abs(bp.InterpolateUm(t) - f(t)));
          }
        }
        EXPECT_LE(worst, tol) << "p " << p << " A " << a << " tol " << tol;
        EXPECT_GT(bp.effective_tolerance_um, 0.5 * tol);
      }
    }
  }
}

TEST(Breakpoints, SteepStartCostsSamplesNotTolerance) {
  // The start's bound is met by subdividing the start, not by lowering the tolerance of every
  // chord: a 30 um / 250 s arctan curve with p = 0.882 over the reference screw's 7655 s keeps
  // almost the whole tolerance (a bound applied to the whole grid left 0.466 of 0.5 um).
  const fit::ArctanCurve c{30.0, 250.0, fit::kDefaultShapeK, 0.882};
  BreakpointOptions o;
  o.forced_times_s.assign(1, c.settle_time_s);
  const Breakpoints bp =
      ChooseBreakpoints([&](double t) { return c.ElongationUm(t); }, 0.0, 7655.0, o);
  EXPECT_GT(bp.effective_tolerance_um, 0.48);
  EXPECT_LE(bp.max_deviation_um, bp.effective_tolerance_um);
}

TEST(Breakpoints, DenseWhileMovingSparseOnPlateau) {
  const fit::ArctanCurve c{50.0, 250.0, 5.0};
  BreakpointOptions o;
  o.forced_times_s.assign(1, c.settle_time_s);
  const Breakpoints bp = ChooseBreakpoints([&](double t) { return c.ElongationUm(t); }, 0, 7000, o);
  // Segment lengths grow while the slope falls: the first is shorter than the last one before t_s.
  const double first = bp.time_s[1] - bp.time_s[0];
  const double before_settle = bp.time_s[bp.size() - 2] - bp.time_s[bp.size() - 3];
  EXPECT_LT(first, before_settle);
  EXPECT_GT(bp.time_s.back() - bp.time_s[bp.size() - 2], 6000.0);
}

TEST(Breakpoints, GreedyCountEqualsExhaustiveMinimumOnSmallGrids) {
  // Reference: the fewest chords through grid samples covering the grid within the same effective
  // tolerance, by dynamic programming over all (a, b) pairs. Plain arctangents (p = 1) with
  // k up to 6, whose check grid mostly stays the uniform one the reference rebuilds; a start that
  // needs extra samples towards t = 0 (a sharp bend within the first step) is left out, and most
  // trials must remain.
  std::mt19937 rng(22);
  std::uniform_real_distribution<double> uk(0.3, 6.0);
  int checked = 0;
  for (int trial = 0; trial < 40; ++trial) {
    fit::ArctanCurve c = RandomCurve(rng);
    c.time_exponent = 1.0;
    c.shape_k = uk(rng);
    const double t_end = 1.2 * c.settle_time_s;
    const int steps = 80;
    BreakpointOptions o;
    o.check_step_s = t_end / steps;
    o.tolerance_um = 0.02 * c.max_elongation_um;
    o.forced_times_s.clear();
    auto f = [&](double t) { return c.ElongationUm(t); };
    const Breakpoints bp = ChooseBreakpoints(f, 0.0, t_end, o);
    ASSERT_GE(bp.grid_samples, static_cast<std::size_t>(steps + 1));
    if (bp.grid_samples != static_cast<std::size_t>(steps + 1)) continue;
    ++checked;
    std::vector<double> t(steps + 1), l(steps + 1);
    for (int i = 0; i <= steps; ++i) {
      t[i] = i == steps ? t_end : t_end * i / steps;
      l[i] = f(t[i]);
    }
    auto fits = [&](int a, int b) {
      for (int i = a + 1; i < b; ++i)
        if (std::abs(l[a] + (l[b] - l[a]) * (t[i] - t[a]) / (t[b] - t[a]) - l[i]) >
            bp.effective_tolerance_um)
          return false;
      return true;
    };
    std::vector<int> best(steps + 1, 1 << 20);
    best[0] = 0;
    for (int b = 1; b <= steps; ++b)
      for (int a = 0; a < b; ++a)
        if (best[a] + 1 < best[b] && fits(a, b)) best[b] = best[a] + 1;
    EXPECT_EQ(static_cast<int>(bp.size()) - 1, best[steps]) << "trial " << trial;
  }
  EXPECT_GE(checked, 30);
}

TEST(Breakpoints, UniformCountIsTheSmallestUniformSpacingThatMeetsTheBound) {
  std::mt19937 rng(23);
  int unreachable = 0;
  for (int trial = 0; trial < 30; ++trial) {
    const fit::ArctanCurve c = RandomCurve(rng);
    const double t_end = 4.0 * c.settle_time_s;
    BreakpointOptions o;
    o.tolerance_um = 0.5;
    o.check_step_s = 0.5;
    o.forced_times_s.assign(1, c.settle_time_s);
    auto f = [&](double t) { return c.ElongationUm(t); };
    const Breakpoints bp = ChooseBreakpoints(f, 0.0, t_end, o);
    const std::size_t n = UniformPointCount(f, 0.0, t_end, o);
    if (n == 0) {  // a steep start (small p) that 1e6 uniform points cannot follow
      ++unreachable;
      EXPECT_LT(c.time_exponent, 0.7);
      continue;
    }
    ASSERT_GE(n, 2u);
    EXPECT_GE(n, bp.size()) << "uniform spacing cannot beat the adaptive points";
    auto uniform_error = [&](std::size_t count) {
      std::vector<double> ut(count), uv(count);
      for (std::size_t j = 0; j < count; ++j) {
        ut[j] = j + 1 == count ? t_end : t_end * j / (count - 1);
        uv[j] = f(ut[j]);
      }
      // Resolve every uniform interval (steep starts, p < 1, need very many points) and look at
      // the kink t_s itself, where the error of a chord across it peaks.
      const double grid_error =
          MaxInterpolationErrorUm(f, ut, uv, std::min(0.05, t_end / (count - 1) / 20));
      const auto hi = std::upper_bound(ut.begin(), ut.end(), c.settle_time_s) - ut.begin();
      const double at_kink = uv[hi - 1] + (uv[hi] - uv[hi - 1]) * (c.settle_time_s - ut[hi - 1]) /
                                              (ut[hi] - ut[hi - 1]);
      // And sample the first interval densely: a start like t^p bulges most at p^(1/(1-p)) of it.
      double first_error = 0;
      for (int i = 1; i < 100000; ++i) {
        const double t = ut[1] * i / 100000.0;
        first_error = std::max(first_error, std::abs(uv[0] + (uv[1] - uv[0]) * t / ut[1] - f(t)));
      }
      return std::max({grid_error, first_error, std::abs(at_kink - f(c.settle_time_s))});
    };
    EXPECT_LE(uniform_error(n), o.tolerance_um);
    if (n > 2) {
      EXPECT_GT(uniform_error(n - 1), bp.effective_tolerance_um);
    }
  }
  EXPECT_LE(unreachable, 5);
}

TEST(Breakpoints, StraightLineNeedsTwoPoints) {
  const Breakpoints bp = ChooseBreakpoints([](double t) { return 3.0 + 0.2 * t; }, 0.0, 1000.0);
  EXPECT_EQ(bp.size(), 2u);
  EXPECT_EQ(UniformPointCount([](double t) { return 3.0 + 0.2 * t; }, 0.0, 1000.0), 2u);
}

TEST(Breakpoints, BadInputThrows) {
  auto f = [](double t) { return t; };
  BreakpointOptions o;
  o.tolerance_um = -0.5;
  EXPECT_THROW(ChooseBreakpoints(f, 0, 10, o), InputError);
  o.tolerance_um = 0.5;
  o.check_step_s = 0;
  EXPECT_THROW(ChooseBreakpoints(f, 0, 10, o), InputError);
  o.check_step_s = 0.1;
  EXPECT_THROW(ChooseBreakpoints(f, 10, 10, o), InputError);
  EXPECT_THROW(ChooseBreakpoints([](double) { return std::nan(""); }, 0, 10, o), InputError);
  o.max_grid_samples = 50;
  EXPECT_THROW(ChooseBreakpoints(f, 0, 10, o), InputError);
  // A tolerance the curvature margin eats even on the finest allowed grid.
  BreakpointOptions coarse;
  coarse.tolerance_um = 1e-9;
  coarse.check_step_s = 5.0;
  coarse.max_grid_samples = 100000;
  const auto sine = [](double t) { return 100 * std::sin(t / 10); };
  EXPECT_THROW(ChooseBreakpoints(sine, 0, 100, coarse), InputError);
  // A small tolerance on a coarse grid is met by refining the grid.
  coarse.tolerance_um = 1e-3;
  const Breakpoints fine = ChooseBreakpoints(sine, 0, 100, coarse);
  EXPECT_LT(fine.check_step_s, 5.0);
  EXPECT_LE(MaxInterpolationErrorUm(sine, fine.time_s, fine.value_um, 1e-3), 1e-3);
}

}  // namespace
}  // namespace whirl::interp
