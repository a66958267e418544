// Synthetic fields, the choice between cubic and B-spline, and the 840D axis line.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "surface/choice.h"
#include "surface/line840d.h"
#include "synthetic/surface.h"

namespace whirl::surface {
namespace {

TEST(Synthetic, SmoothFieldSpans10To40UmWithAllParts) {
  synthetic::SyntheticOptions o;
  o.noise_um = 0;
  double lo = 1e9, hi = -1e9;
  for (const auto& p : synthetic::SyntheticPoints(o))
    lo = std::min(lo, p.error_um), hi = std::max(hi, p.error_um);
  EXPECT_DOUBLE_EQ(lo, 10);  // at (0, 0)
  EXPECT_DOUBLE_EQ(hi, 38);  // at (length_x, length_y): 10+10+6+4+3-2+5+2
  // The noise has the stated standard deviation.
  synthetic::SyntheticOptions n = o;
  n.noise_um = 1.5, n.nx = 60, n.ny = 60;
  double sum2 = 0;
  const auto pts = synthetic::SyntheticPoints(n);
  for (const auto& p : pts) sum2 += std::pow(p.error_um - synthetic::SyntheticErrorUm(n, p.x_mm, p.y_mm), 2);
  EXPECT_NEAR(std::sqrt(sum2 / pts.size()), 1.5, 0.1);
}

TEST(Choice, CubicFieldIsFittedExactlyAndNotFlagged) {
  synthetic::SyntheticOptions o;
  o.noise_um = 0;
  const MethodComparison c = CompareMethods(synthetic::SyntheticPoints(o));
  ASSERT_TRUE(c.cubic_available && c.bspline_available);
  EXPECT_LT(c.cubic_loo.max_abs_um, 1e-9);
  EXPECT_FALSE(c.cubic_oscillates) << c.note;
  EXPECT_EQ(c.recommended, Method::kCubic) << c.reason;
}

TEST(Choice, SmoothNoisyFieldPrefersTheCubic) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    synthetic::SyntheticOptions o;
    o.seed = seed;
    const MethodComparison c = CompareMethods(synthetic::SyntheticPoints(o));
    EXPECT_EQ(c.recommended, Method::kCubic) << "seed " << seed << ": " << c.reason;
  }
}

TEST(Choice, OnTheBumpFieldTheBsplineLeaveOneOutIsLower) {
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    synthetic::SyntheticOptions o;
    o.field = synthetic::SyntheticField::kBump;
    o.seed = seed;
    const MethodComparison c = CompareMethods(synthetic::SyntheticPoints(o));
    EXPECT_LT(c.bspline_loo_common.rms_um, c.cubic_loo_common.rms_um) << "seed " << seed;
    EXPECT_EQ(c.recommended, Method::kBspline) << c.reason;
  }
}

// Runge's function along x: the cubic swings beyond the measured range; the note says so.
TEST(Choice, RungeFieldRaisesTheOscillationNote) {
  std::vector<SurfacePoint> p;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 13; ++j) {
      const double u = -1 + 2.0 * j / 12;
      p.push_back({400 + 400 * u, 100.0 * i, 10 + 25 / (1 + 25 * u * u)});
    }
  const MethodComparison c = CompareMethods(p);
  EXPECT_TRUE(c.cubic_oscillates);
  EXPECT_GT(c.cubic_overshoot_um, 0.1 * c.measured_range_um);
  EXPECT_NE(c.note.find("oscillates at the edges"), std::string::npos) << c.note;
  EXPECT_EQ(c.recommended, Method::kBspline);
  EXPECT_LT(c.bspline_loo_common.rms_um, 0.5 * c.cubic_loo_common.rms_um);
}

TEST(Choice, ScatteredPointsFallBackToTheCubic) {
  synthetic::SyntheticOptions o;
  auto pts = synthetic::SyntheticPoints(o);
  pts.pop_back();  // no longer a complete grid
  const MethodComparison c = CompareMethods(pts);
  EXPECT_FALSE(c.bspline_available);
  EXPECT_NE(c.bspline_refusal.find("irregular grid"), std::string::npos);
  EXPECT_EQ(c.recommended, Method::kCubic);
}

// E = c0 + k x + q y on a grid: the whole-table line along x has slope k; what it leaves is
// q (y - mean y), so max = |q| (ymax - ymin) / 2 and RMS = |q| * std of the sampled y.
TEST(AxisLine, PlaneHasTheClosedFormLineAndResidual) {
  const double c0 = 12, k = 0.02, q = -0.03;
  std::vector<SurfacePoint> pts;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 6; ++j) {
      const double x = 100 + 120.0 * j, y = -50 + 100.0 * i;
      pts.push_back({x, y, c0 + k * x + q * y});
    }
  for (Method m : {Method::kCubic, Method::kBspline}) {
    const SurfaceFit f = FitSurface(pts, {m, 3});
    AxisLineOptions o;
    o.samples = 11;
    const AxisLine l = FitAxisLine(f.surface, o);
    EXPECT_NEAR(l.slope_um_per_mm, k, 1e-9);
    EXPECT_NEAR(l.reference_mm, 100, 0);
    EXPECT_NEAR(l.value_at_ref_um, c0 + k * 100 + q * 150, 1e-8);  // mean y = 150
    EXPECT_NEAR(l.uncorrected_max_abs_um, std::abs(q) * 200, 1e-8);
    double var = 0;
    for (int s = 0; s < 11; ++s) var += std::pow(400.0 * s / 10 - 200, 2) / 11;
    EXPECT_NEAR(l.uncorrected_rms_um, std::abs(q) * std::sqrt(var), 1e-8);
    // Setting data, subtract convention: dK = -line / 1000 at P = offset + x.
    EXPECT_NEAR(l.sd43910, -k / 1000, 1e-15);
    EXPECT_NEAR(l.sd43920_mm, 100, 0);
    for (double x : {100.0, 333.0, 700.0})
      EXPECT_NEAR(l.CompensationMm(x), -(l.value_at_ref_um + k * (x - 100)) / 1000, 1e-12);
    // One traverse at y = 250: exact, nothing left.
    o.at_mm = 250;
    o.sign = interp::SignConvention::kAdd;
    o.machine_offset_mm = -400;
    const AxisLine t = FitAxisLine(f.surface, o);
    EXPECT_NEAR(t.uncorrected_max_abs_um, 0, 1e-8);
    EXPECT_NEAR(t.sd43900_mm, (c0 + k * 100 + q * 250) / 1000, 1e-12);
    EXPECT_NEAR(t.sd43920_mm, -300, 1e-12);
    EXPECT_NEAR(t.CompensationMm(-400 + 550), (c0 + k * 550 + q * 250) / 1000, 1e-12);
    // Along y: slope q.
    AxisLineOptions oy;
    oy.along = 'y';
    oy.axis = "Y1";
    EXPECT_NEAR(FitAxisLine(f.surface, oy).slope_um_per_mm, q, 1e-9);
  }
}

TEST(AxisLine, SlopeBeyondMd32760IsCappedAndCostsAccuracy) {
  std::vector<SurfacePoint> pts;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) pts.push_back({100.0 * j, 100.0 * i, 20.0 * j});  // 0.2 um/mm
  const SurfaceFit f = FitSurface(pts, {Method::kBspline, 3});
  AxisLineOptions o;
  o.md32760 = 1e-4;  // 0.1 um/mm
  const AxisLine l = FitAxisLine(f.surface, o);
  EXPECT_TRUE(l.slope_capped);
  EXPECT_NEAR(std::abs(l.sd43910), 1e-4, 1e-15);
  EXPECT_NEAR(l.uncapped_sd43910, -0.2 / 1000, 1e-12);
  EXPECT_NEAR(l.uncorrected_max_abs_um, 0.1 * 150, 1e-8);  // (0.2 - 0.1) um/mm * half travel
  o.md32760 = 0.2;
  EXPECT_THROW(FitAxisLine(f.surface, o), InputError);  // beyond the 0.10 range of MD32760
  o.md32760 = 0.01;
  o.at_mm = 400;  // outside y 0..300
  EXPECT_THROW(FitAxisLine(f.surface, o), InputError);
  o.at_mm.reset();
  o.axis = "X;M30";
  EXPECT_THROW(FitAxisLine(f.surface, o), InputError);
}

}  // namespace
}  // namespace whirl::surface
