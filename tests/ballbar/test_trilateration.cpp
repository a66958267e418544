// Trilateration (Shang, Ruan and Zhang, eqs. 11-17): hand example, round trips, Jacobian against
// finite differences, degenerate geometry, placement advice.
#include <gtest/gtest.h>

#include "support/expect_error.h"

#include <Eigen/Geometry>
#include <cmath>

#include "ballbar/trilateration.h"
#include "core/error.h"
#include "core/random.h"
#include "support/eigen_near.h"

namespace whirl::ballbar {
namespace {

using Eigen::Vector3d;
constexpr double kPi = 3.14159265358979323846;

double U(Rng& r, double lo, double hi) { return lo + (hi - lo) * r.Uniform(); }

// A random pivot triangle on a plane tilted up to 30 degrees, and a tool ball above it.
struct Case {
  PivotCentres pivots;
  Vector3d ball;
};
Case RandomCase(Rng& r) {
  const Vector3d centre(U(r, -500, 500), U(r, -500, 500), U(r, -200, 200));
  const Vector3d tilt(U(r, -0.5, 0.5), U(r, -0.5, 0.5), 1);  // plane normal within ~35 deg
  const Vector3d n = tilt.normalized();
  const Vector3d a = n.cross(Vector3d::UnitX()).normalized(), b = n.cross(a);
  Case c;
  double angle = U(r, 0, 6.28);
  for (auto& p : c.pivots) {
    const double rad = U(r, 60, 200);
    p = centre + rad * (std::cos(angle) * a + std::sin(angle) * b);
    angle += U(r, 1.6, 2.5);  // spread around the circle
  }
  c.ball = centre + U(r, -40, 40) * a + U(r, -40, 40) * b + U(r, 40, 250) * n;
  return c;
}

TEST(Trilateration, HandComputedExampleFollowsEachEquation) {
  // B1 (0,0,0), B2 (100,0,0), B3 (0,100,0), P (30,40,50): L^2 = 5000, 9000, 7000.
  const PivotCentres b{Vector3d(0, 0, 0), Vector3d(100, 0, 0), Vector3d(0, 100, 0)};
  const PivotFrame f = MakePivotFrame(b);
  EXPECT_DOUBLE_EQ(f.lb1_mm, 100);
  EXPECT_NEAR(f.lb2_mm, std::sqrt(20000.0), 1e-12);
  EXPECT_DOUBLE_EQ(f.lb3_mm, 100);
  EXPECT_NEAR(f.xb_mm, 0, 1e-12);    // (13): (10000 - 20000 + 10000) / 200
  EXPECT_NEAR(f.cb_mm, 100, 1e-12);  // (14)
  const Vector3d l(std::sqrt(5000.0), std::sqrt(9000.0), std::sqrt(7000.0));
  // (11) x = (5000 - 9000 + 10000)/200 = 30; (12) c1^2 = 4100; (15) d1^2 = 5000;
  // (16) y = (5000 - 7000 + 10000)/200 = 40; (17) z = sqrt(4100 - 1600) = 50.
  EXPECT_TRUE(test::AllNear(TrilaterateLocal(f, l), Vector3d(30, 40, 50), 0, 1e-12));
  EXPECT_TRUE(test::AllNear(Trilaterate(f, l), Vector3d(30, 40, 50), 0, 1e-12));
}

TEST(Trilateration, RoundTripPositionLengthsPositionTo1e9mm) {
  Rng r(7);
  double worst = 0;
  for (int i = 0; i < 2000; ++i) {
    const Case c = RandomCase(r);
    const PivotFrame f = MakePivotFrame(c.pivots);
    const Vector3d back = Trilaterate(f, BarLengths(c.pivots, c.ball));
    worst = std::max(worst, (back - c.ball).cwiseAbs().maxCoeff());
  }
  RecordProperty("worst_round_trip_mm", testing::PrintToString(worst));
  EXPECT_LT(worst, 1e-9) << "worst round-trip error " << worst << " mm";
}

TEST(Trilateration, PivotOrderDoesNotMatterForTheSide) {
  // Clockwise pivots (seen from +Z) flip the paper's z axis; the root stays on the +Z side.
  const PivotCentres ccw{Vector3d(0, 0, 0), Vector3d(100, 0, 0), Vector3d(50, 90, 0)};
  const PivotCentres cw{ccw[0], ccw[2], ccw[1]};
  const Vector3d ball(40, 30, 80);
  for (const auto& b : {ccw, cw})
    EXPECT_TRUE(test::AllNear(Trilaterate(MakePivotFrame(b), BarLengths(b, ball)), ball, 0, 1e-10));
}

TEST(Trilateration, JacobianMatchesFiniteDifferencesOfEquations11To17) {
  Rng r(11);
  for (int i = 0; i < 200; ++i) {
    const Case c = RandomCase(r);
    const PivotFrame f = MakePivotFrame(c.pivots);
    const Vector3d l = BarLengths(c.pivots, c.ball);
    Eigen::Matrix3d fd;
    const double h = 1e-4;
    for (int k = 0; k < 3; ++k) {
      Vector3d lp = l, lm = l;
      lp(k) += h;
      lm(k) -= h;
      fd.col(k) = (Trilaterate(f, lp) - Trilaterate(f, lm)) / (2 * h);
    }
    ASSERT_TRUE(test::AllNear(PositionJacobian(c.pivots, c.ball), fd, 1e-6, 1e-7)) << "case " << i;
  }
}

TEST(Trilateration, DegenerateGeometryIsAClearErrorNotNaN) {
  const PivotCentres line{Vector3d(0, 0, 0), Vector3d(100, 0, 0), Vector3d(200, 1, 0)};
  ExpectInputError([&] { MakePivotFrame(line); }, "collinear");
  const PivotCentres same{Vector3d(0, 0, 0), Vector3d(0, 0, 0), Vector3d(0, 100, 0)};
  ExpectInputError([&] { MakePivotFrame(same); }, "collinear");
  const PivotCentres wall{Vector3d(0, 0, 0), Vector3d(100, 0, 0), Vector3d(0, 0, 100)};
  ExpectInputError([&] { MakePivotFrame(wall); }, "tilted");

  const PivotCentres b{Vector3d(0, 0, 0), Vector3d(100, 0, 0), Vector3d(50, 90, 0)};
  const PivotFrame f = MakePivotFrame(b);
  // |L1 - L2| > |B1B2|: eq. 12's radicand is negative.
  ExpectInputError([&] { TrilaterateLocal(f, Vector3d(300, 150, 200)); }, "eq. 12");
  // L3 far too long for the other two: eq. 17's radicand is negative.
  ExpectInputError([&] { TrilaterateLocal(f, Vector3d(100, 100, 400)); }, "eq. 17");
  // Tool ball 2 mm above the pivots' plane.
  ExpectInputError([&] { TrilaterateLocal(f, BarLengths(b, Vector3d(50, 30, 2))); },
                   "above the pivots' plane");
  ExpectInputError([&] { TrilaterateLocal(f, Vector3d(-1, 100, 100)); }, "positive");
  // Just above the limit it works.
  EXPECT_NO_THROW(TrilaterateLocal(f, BarLengths(b, Vector3d(50, 30, 10))));
}

TEST(Placement, IdealLayoutHasConditionOneAndUnitGain) {
  const double bar = 150, h = bar / std::sqrt(3.0), rad = bar * std::sqrt(2.0 / 3.0);
  PivotCentres b;
  for (int i = 0; i < 3; ++i) {
    const double a = (210 + 120 * i) * kPi / 180;
    b[i] = Vector3d(rad * std::cos(a), rad * std::sin(a), -h);
  }
  const PlacementAdvice a = AdvisePlacement(MakePivotFrame(b), Vector3d::Zero());
  EXPECT_NEAR(a.condition_number, 1, 1e-9);
  EXPECT_TRUE(test::AllNear(a.noise_gain, Vector3d::Ones(), 1e-9));
  EXPECT_NEAR(a.ideal_height_mm, h, 1e-9);
  EXPECT_NEAR(a.height_mm, h, 1e-9);
  EXPECT_NEAR(a.mean_radius_mm, rad, 1e-9);
  EXPECT_EQ(a.rating, "good");
}

TEST(Placement, LowBallIsPoorAndAdviceSaysRaiseIt) {
  const PivotCentres b{Vector3d(-150, -90, 0), Vector3d(150, -90, 0), Vector3d(0, 170, 0)};
  const PlacementAdvice a = AdvisePlacement(MakePivotFrame(b), Vector3d(0, 0, 15));
  EXPECT_GT(a.condition_number, 5);
  EXPECT_EQ(a.rating, "poor");
  EXPECT_NE(a.advice.find("raise"), std::string::npos) << a.advice;
  EXPECT_GT(a.noise_gain.z(), 3);  // z noise grows like L / h
  const PlacementAdvice tight = AdvisePlacement(
      MakePivotFrame({Vector3d(-10, -6, 0), Vector3d(10, -6, 0), Vector3d(0, 11, 0)}),
      Vector3d(0, 0, 150));
  EXPECT_EQ(tight.rating, "poor");
  EXPECT_NE(tight.advice.find("spread"), std::string::npos) << tight.advice;
}

TEST(Placement, NoiseGainIsTheSdPerUnitReadingSd) {
  // Property: the gain predicts the scatter of positions from noisy lengths (Monte Carlo).
  Rng r(3);
  const Case c = RandomCase(r);
  const PivotFrame f = MakePivotFrame(c.pivots);
  const PlacementAdvice a = AdvisePlacement(f, c.ball);
  const Vector3d l = BarLengths(c.pivots, c.ball);
  const double sd = 1e-4;
  Vector3d ss = Vector3d::Zero();
  const int n = 20000;
  for (int i = 0; i < n; ++i) {
    const Vector3d noisy = l + sd * Vector3d(r.Normal(), r.Normal(), r.Normal());
    ss += (Trilaterate(f, noisy) - c.ball).cwiseAbs2();
  }
  const Vector3d mc = (ss / n).cwiseSqrt() / sd;
  EXPECT_TRUE(test::AllNear(mc, a.noise_gain, 0.03))
      << mc.transpose() << " vs " << a.noise_gain.transpose();
}

}  // namespace
}  // namespace whirl::ballbar
