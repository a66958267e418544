// Cubic polynomial and B-spline surfaces against closed forms and invariants (surface/*.h).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "core/error.h"
#include "support/eigen_near.h"
#include "surface/bspline.h"
#include "surface/cubic.h"
#include "surface/surface.h"

namespace whirl::surface {
namespace {

std::vector<SurfacePoint> Scattered(std::mt19937_64& rng, int n, double lx, double ly) {
  std::uniform_real_distribution<double> ux(-0.3 * lx, lx), uy(100, 100 + ly);
  std::vector<SurfacePoint> p;
  for (int k = 0; k < n; ++k) p.push_back({ux(rng), uy(rng), 0});
  return p;
}

double CubicMm(const std::array<double, 10>& a, double x, double y) {
  double e = 0;
  for (int k = 0; k < kCubicTerms; ++k)
    e += a[k] * std::pow(x, kCubicExponents[k][0]) * std::pow(y, kCubicExponents[k][1]);
  return e;
}

TEST(Cubic, ReproducesAnyCubicExactly) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01;
  for (int rep = 0; rep < 50; ++rep) {
    // Coefficients scaled so every term is O(10 um) over a 1 m table.
    std::array<double, 10> a{};
    for (int k = 0; k < kCubicTerms; ++k)
      a[k] = 10 * n01(rng) / std::pow(1000.0, kCubicExponents[k][0] + kCubicExponents[k][1]);
    auto pts = Scattered(rng, 10 + rep, 1000, 600);
    for (auto& p : pts) p.error_um = CubicMm(a, p.x_mm, p.y_mm);
    const CubicFit f = FitCubic(pts);
    for (const auto& p : Scattered(rng, 20, 1000, 600))
      EXPECT_NEAR(f.surface.Evaluate(p.x_mm, p.y_mm), CubicMm(a, p.x_mm, p.y_mm), 1e-8);
    const auto got = f.surface.CoefficientsMm();
    for (int k = 0; k < kCubicTerms; ++k) EXPECT_NEAR(got[k], a[k], 1e-9 * (std::abs(a[k]) + 1e-8));
    for (double r : f.residual_um) EXPECT_NEAR(r, 0, 1e-9);
  }
}

TEST(Cubic, CoefficientsInMmEvaluateLikeTheNormalizedForm) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  for (int rep = 0; rep < 20; ++rep) {
    CubicSurface s;
    for (double& b : s.b) b = 10 * n01(rng);
    s.x_center_mm = 500 * n01(rng), s.y_center_mm = 500 * n01(rng);
    s.x_half_range_mm = 100 + 400 * std::abs(n01(rng));
    s.y_half_range_mm = 100 + 400 * std::abs(n01(rng));
    const auto a = s.CoefficientsMm();
    for (const auto& p : Scattered(rng, 10, 1000, 1000))
      EXPECT_NEAR(CubicMm(a, p.x_mm, p.y_mm), s.Evaluate(p.x_mm, p.y_mm),
                  1e-9 * (1 + std::abs(s.Evaluate(p.x_mm, p.y_mm))));
  }
}

TEST(Cubic, LeaveOneOutMatchesAnExplicitRefit) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  auto pts = Scattered(rng, 25, 800, 500);
  for (auto& p : pts) p.error_um = 20 + 0.01 * p.x_mm + 3 * n01(rng);
  const CubicFit f = FitCubic(pts);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    auto rest = pts;
    rest.erase(rest.begin() + static_cast<long>(i));
    const double pred = FitCubic(rest).surface.Evaluate(pts[i].x_mm, pts[i].y_mm);
    EXPECT_NEAR(f.loo_error_um[i], pts[i].error_um - pred, 1e-8) << "point " << i;
  }
}

TEST(Cubic, ExactlyTenPointsHaveNoLeaveOneOut) {
  std::mt19937_64 rng(2);
  auto pts = Scattered(rng, 10, 800, 500);
  for (auto& p : pts) p.error_um = p.x_mm * 0.01;
  const CubicFit f = FitCubic(pts);
  for (double e : f.loo_error_um) EXPECT_TRUE(std::isnan(e));
  EXPECT_TRUE(std::isnan(StatsOf(f.loo_error_um).rms_um));
}

TEST(Cubic, RefusesFewerThanTenDistinctPositions) {
  std::mt19937_64 rng(1);
  auto pts = Scattered(rng, 9, 800, 500);
  pts.push_back(pts[0]);  // 10 rows, 9 positions
  pts.push_back(pts[1]);
  try {
    FitCubic(pts);
    FAIL() << "accepted 9 distinct positions";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("9 distinct positions"), std::string::npos) << e.what();
  }
}

TEST(Cubic, RefusesPointsOnThreeLines) {
  // (x - 0)(x - 100)(x - 200) vanishes on all of them: rank 9.
  std::vector<SurfacePoint> pts;
  for (double x : {0.0, 100.0, 200.0})
    for (int k = 0; k < 5; ++k) pts.push_back({x, 50.0 * k, 1.0});
  try {
    FitCubic(pts);
    FAIL() << "accepted a rank-deficient design";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("only 9 of the 10"), std::string::npos) << e.what();
  }
}

TEST(Cubic, ConditionNumberIsTranslationInvariantInNormalizedCoordinates) {
  std::mt19937_64 rng(8);
  auto pts = Scattered(rng, 30, 800, 500);
  for (auto& p : pts) p.error_um = p.y_mm * 0.02;
  const CubicFit a = FitCubic(pts);
  for (auto& p : pts) p.x_mm += 5000, p.y_mm -= 3000;
  const CubicFit b = FitCubic(pts);
  EXPECT_NEAR(a.condition_number, b.condition_number, 1e-6 * a.condition_number);
  EXPECT_GE(a.condition_number, 1.0);
  EXPECT_GT(b.condition_number_mm, 1e6 * b.condition_number);  // why the fit normalizes
}

// --- B-spline ----------------------------------------------------------------------------------

TEST(Knots, ClampedAveragedByHand) {
  EXPECT_EQ(ClampedAveragedKnots({0, 1, 2, 3, 4}, 3),
            (std::vector<double>{0, 0, 0, 0, 2, 4, 4, 4, 4}));
  EXPECT_EQ(ClampedAveragedKnots({0, 1, 3, 6}, 2), (std::vector<double>{0, 0, 0, 2, 6, 6, 6}));
  EXPECT_EQ(ClampedAveragedKnots({0, 10, 30}, 1), (std::vector<double>{0, 0, 10, 30, 30}));
  EXPECT_THROW(ClampedAveragedKnots({0, 1, 2}, 3), InputError);
  EXPECT_THROW(ClampedAveragedKnots({0, 2, 1, 3}, 1), InputError);
}

TEST(Basis, WithoutInteriorKnotsIsBernstein) {
  // n = p + 1 points: clamped knots [a..a, b..b], the basis is the Bernstein polynomials.
  for (int p = 1; p <= kMaxDegree; ++p) {
    std::vector<double> coords;
    for (int k = 0; k <= p; ++k) coords.push_back(100 + 50.0 * k * k);
    const auto t = ClampedAveragedKnots(coords, p);
    const double a = coords.front(), b = coords.back();
    for (int s = 0; s <= 20; ++s) {
      const double x = a + (b - a) * s / 20.0, u = (x - a) / (b - a);
      for (int j = 0; j <= p; ++j) {
        double binom = 1;
        for (int i = 1; i <= j; ++i) binom = binom * (p - j + i) / i;
        EXPECT_NEAR(BasisFunction(t, j, p, x), binom * std::pow(u, j) * std::pow(1 - u, p - j),
                    1e-12)
            << "p " << p << " j " << j << " x " << x;
      }
    }
  }
}

TEST(Basis, PartitionOfUnityNonNegativeAndLastIsOneAtTheUpperEnd) {
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> gap(5, 120);
  for (int p = 1; p <= kMaxDegree; ++p) {
    std::vector<double> c{-50};
    for (int k = 0; k < 9; ++k) c.push_back(c.back() + gap(rng));
    const auto t = ClampedAveragedKnots(c, p);
    for (int s = 0; s <= 200; ++s) {
      const double x = c.front() + (c.back() - c.front()) * s / 200.0;
      const Eigen::VectorXd row = BasisRow(t, p, x);
      EXPECT_NEAR(row.sum(), 1.0, 1e-12) << "p " << p << " x " << x;
      EXPECT_GE(row.minCoeff(), 0.0);
    }
    const Eigen::VectorXd end = BasisRow(t, p, c.back());
    EXPECT_EQ(end(end.size() - 1), 1.0);
    EXPECT_EQ(end.head(end.size() - 1).cwiseAbs().sum(), 0.0);
  }
}

std::vector<double> RandomLines(std::mt19937_64& rng, int n, double start) {
  std::uniform_real_distribution<double> gap(20, 150);
  std::vector<double> v{start};
  for (int k = 1; k < n; ++k) v.push_back(v.back() + gap(rng));
  return v;
}

std::vector<SurfacePoint> GridPoints(const std::vector<double>& xs, const std::vector<double>& ys,
                                     const std::function<double(double, double)>& f) {
  std::vector<SurfacePoint> p;
  for (double y : ys)
    for (double x : xs) p.push_back({x, y, f(x, y)});
  return p;
}

TEST(Bspline, InterpolatesEveryGridPoint) {
  std::mt19937_64 rng(21);
  std::normal_distribution<double> n01;
  for (int p = 1; p <= kMaxDegree; ++p)
    for (int rep = 0; rep < 5; ++rep) {
      const auto xs = RandomLines(rng, p + 1 + rep * 2, 0), ys = RandomLines(rng, p + 2 + rep, 30);
      auto pts = GridPoints(xs, ys, [&](double, double) { return 25 + 10 * n01(rng); });
      std::shuffle(pts.begin(), pts.end(), rng);  // the order of the rows does not matter
      const BsplineFit f = FitBsplinePoints(pts, p);
      for (const auto& q : pts) EXPECT_NEAR(f.surface.Evaluate(q.x_mm, q.y_mm), q.error_um, 1e-9);
      for (double r : f.residual_um) EXPECT_NEAR(r, 0, 1e-9);
    }
}

TEST(Bspline, ReproducesPolynomialsUpToItsDegree) {
  std::mt19937_64 rng(22);
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u01(0, 1);
  for (int p = 1; p <= kMaxDegree; ++p)
    for (int rep = 0; rep < 4; ++rep) {
      Eigen::MatrixXd c(p + 1, p + 1);
      for (int a = 0; a <= p; ++a)
        for (int b = 0; b <= p; ++b) c(a, b) = 10 * n01(rng);
      auto f = [&](double x, double y) {
        double e = 0;
        for (int a = 0; a <= p; ++a)
          for (int b = 0; b <= p; ++b) e += c(a, b) * std::pow(x / 800, a) * std::pow(y / 800, b);
        return e;
      };
      const auto xs = RandomLines(rng, p + 1 + 2 * rep, 0), ys = RandomLines(rng, p + 1 + rep, -40);
      const BsplineFit fit = FitBsplinePoints(GridPoints(xs, ys, f), p);
      for (int k = 0; k < 50; ++k) {
        const double x = xs.front() + (xs.back() - xs.front()) * u01(rng);
        const double y = ys.front() + (ys.back() - ys.front()) * u01(rng);
        EXPECT_NEAR(fit.surface.Evaluate(x, y), f(x, y), 1e-9 * (1 + std::abs(f(x, y))))
            << "p " << p << " at " << x << ", " << y;
      }
      // The leave-line-out prediction reproduces it too (where defined).
      for (double e : fit.loo_error_um) {
        if (!std::isnan(e)) {
          EXPECT_NEAR(e, 0, 1e-8);
        }
      }
    }
}

TEST(Bspline, WeightsSolveTheFullMnSystem) {
  std::mt19937_64 rng(23);
  std::normal_distribution<double> n01;
  const auto xs = RandomLines(rng, 6, 0), ys = RandomLines(rng, 5, 0);
  const BsplineFit fit =
      FitBsplinePoints(GridPoints(xs, ys, [&](double, double) { return 20 + 5 * n01(rng); }), 3);
  const auto& s = fit.surface;
  const Eigen::Index m = 5, n = 6;
  // One equation per node (i, j): sum_{r,c} G(r, c) N_r(Y_i) N_c(X_j) = E(i, j).
  Eigen::MatrixXd a(m * n, m * n);
  Eigen::VectorXd e(m * n);
  for (Eigen::Index i = 0; i < m; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const Eigen::VectorXd ny = BasisRow(s.knots_y, 3, ys[static_cast<std::size_t>(i)]);
      const Eigen::VectorXd nx = BasisRow(s.knots_x, 3, xs[static_cast<std::size_t>(j)]);
      for (Eigen::Index r = 0; r < m; ++r)
        for (Eigen::Index c = 0; c < n; ++c) a(i * n + j, r * n + c) = ny(r) * nx(c);
      e(i * n + j) = fit.grid.values(i, j);
    }
  const Eigen::VectorXd g = a.fullPivLu().solve(e);
  Eigen::VectorXd got(m * n);
  for (Eigen::Index r = 0; r < m; ++r)
    for (Eigen::Index c = 0; c < n; ++c) got(r * n + c) = s.weights(r, c);
  EXPECT_TRUE(test::AllNear(got, g, 1e-9, 1e-9));
}

TEST(Bspline, RefusesSmallIrregularGridsAndExtrapolation) {
  const std::vector<double> xs{0, 100, 200, 300}, ys{0, 100, 200};
  auto pts = GridPoints(xs, ys, [](double x, double) { return x / 10; });
  EXPECT_THROW(FitBsplinePoints(pts, 3), InputError);  // 3 rows < p + 1 = 4
  EXPECT_NO_THROW(FitBsplinePoints(pts, 2));
  auto missing = pts;
  missing.erase(missing.begin() + 5);
  try {
    FitBsplinePoints(missing, 2);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("irregular grid"), std::string::npos) << e.what();
  }
  auto twice = pts;
  twice.push_back(pts[3]);
  EXPECT_THROW(FitBsplinePoints(twice, 2), InputError);
  auto off = pts;
  off[4].x_mm = 150;  // a new column with one point
  EXPECT_THROW(FitBsplinePoints(off, 2), InputError);
  const BsplineFit f = FitBsplinePoints(pts, 2);
  EXPECT_NO_THROW(f.surface.Evaluate(300, 200));
  EXPECT_THROW(f.surface.Evaluate(300.01, 100), InputError);
  EXPECT_THROW(f.surface.Evaluate(100, -0.01), InputError);
  EXPECT_THROW(FitBsplinePoints(pts, 0), InputError);
  EXPECT_THROW(FitBsplinePoints(pts, kMaxDegree + 1), InputError);
}

TEST(Bspline, CornersHaveNoLeaveOneOutAndEdgesUseOneDirection) {
  const std::vector<double> xs{0, 100, 200, 300, 400}, ys{0, 100, 200, 300, 400};
  const BsplineFit f =
      FitBsplinePoints(GridPoints(xs, ys, [](double x, double y) { return std::sin(x + y); }), 2);
  // Row-major from (0,0): corners 0, 4, 20, 24.
  for (int corner : {0, 4, 20, 24}) EXPECT_TRUE(std::isnan(f.loo_error_um[corner]));
  for (int k : {1, 2, 3, 5, 6, 12, 18}) EXPECT_FALSE(std::isnan(f.loo_error_um[k])) << k;
}

TEST(SurfaceFile, RoundTripsBothMethodsAndRejectsTamperedKnots) {
  std::mt19937_64 rng(31);
  std::normal_distribution<double> n01;
  const auto xs = RandomLines(rng, 7, 0), ys = RandomLines(rng, 6, 10);
  const auto pts = GridPoints(xs, ys, [&](double, double) { return 20 + 5 * n01(rng); });
  for (Method m : {Method::kCubic, Method::kBspline}) {
    const SurfaceFit f = FitSurface(pts, {m, 3});
    const nlohmann::json j = nlohmann::json::parse(SurfaceFitToJson(f).dump());
    const Surface back = SurfaceFromJson(j, "test");
    for (const auto& p : pts)
      EXPECT_NEAR(back.Evaluate(p.x_mm, p.y_mm), f.surface.Evaluate(p.x_mm, p.y_mm), 1e-12);
    if (m == Method::kBspline) {
      nlohmann::json bad = j;
      bad["bspline"]["knots_x_mm"][4] = 1.0;
      EXPECT_THROW(SurfaceFromJson(bad, "test"), InputError);
      bad = j;
      bad["bspline"]["weights_um"][0].erase(0);
      EXPECT_THROW(SurfaceFromJson(bad, "test"), InputError);
    }
  }
  EXPECT_THROW(SurfaceFromJson({{"schema", "whirl.plan"}}, "test"), InputError);
}

}  // namespace
}  // namespace whirl::surface

namespace whirl::surface {
namespace {

// The B-spline LOO of an interior node, rebuilt from the public API: the mean of the surfaces
// fitted without the node's row and without its column, evaluated at the node.
TEST(Bspline, LeaveOneOutIsTheMeanOfTheRowAndColumnRefits) {
  std::mt19937_64 rng(41);
  std::normal_distribution<double> n01;
  const std::vector<double> xs{0, 90, 200, 330, 400, 520}, ys{0, 70, 150, 260, 300};
  std::vector<SurfacePoint> pts;
  for (double y : ys)
    for (double x : xs) pts.push_back({x, y, 20 + 5 * n01(rng)});
  const BsplineFit fit = FitBsplinePoints(pts, 2);
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const auto& p = pts[k];
    std::vector<double> preds;
    for (int drop_row = 0; drop_row < 2; ++drop_row) {
      const auto& lines = drop_row ? ys : xs;
      const double c = drop_row ? p.y_mm : p.x_mm;
      if (c == lines.front() || c == lines.back()) continue;  // would extrapolate
      std::vector<SurfacePoint> rest;
      for (const auto& q : pts)
        if ((drop_row ? q.y_mm : q.x_mm) != c) rest.push_back(q);
      preds.push_back(FitBsplinePoints(rest, 2).surface.Evaluate(p.x_mm, p.y_mm));
    }
    if (preds.empty()) {
      EXPECT_TRUE(std::isnan(fit.loo_error_um[k])) << k;
    } else {
      double mean = 0;
      for (double v : preds) mean += v / static_cast<double>(preds.size());
      EXPECT_NEAR(fit.loo_error_um[k], p.error_um - mean, 1e-9) << k;
    }
  }
}

}  // namespace
}  // namespace whirl::surface
