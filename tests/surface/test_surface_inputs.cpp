// Surface inputs that used to give nan with exit 0: every number of a surface file in its range
// (naming the field), evaluations that stay finite within those ranges, 840D axis names, the
// synthetic grid within the points limit, a finite --time-min.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "core/error.h"
#include "surface/line840d.h"
#include "surface/per_point.h"
#include "surface/surface.h"
#include "synthetic/surface.h"

namespace whirl::surface {
namespace {

using nlohmann::json;

std::string ErrorOf(const json& j) {
  try {
    SurfaceFromJson(j, "surface file 's.json'");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

json FittedFile(Method m) {
  synthetic::SyntheticOptions o;
  o.nx = 6;
  o.ny = 5;
  return json::parse(SurfaceFitToJson(FitSurface(synthetic::SyntheticPoints(o), {m, 3})).dump());
}

// Each number of the file, set to a value outside its range, is refused naming the field as the
// file writes it; the fitted file itself reads back.
TEST(SurfaceInputs, EveryNumberOfAFileIsRangeChecked) {
  const json cubic = FittedFile(Method::kCubic), spline = FittedFile(Method::kBspline);
  ASSERT_EQ(ErrorOf(cubic), "");
  ASSERT_EQ(ErrorOf(spline), "");
  struct Case {
    const json* base;
    json::json_pointer at;
    double value;
    const char* field;
  };
  const Case cases[] = {
      {&cubic, json::json_pointer("/cubic/x_center_mm"), 1e308, "cubic.x_center_mm = 1e+308"},
      {&cubic, json::json_pointer("/cubic/y_center_mm"), -1e308, "cubic.y_center_mm = -1e+308"},
      {&cubic, json::json_pointer("/cubic/x_half_range_mm"), 1e-300, "cubic.x_half_range_mm"},
      {&cubic, json::json_pointer("/cubic/y_half_range_mm"), 1e308, "cubic.y_half_range_mm"},
      {&cubic, json::json_pointer("/cubic/b_um/7"), 1e300, "cubic.b_um[7] = 1e+300"},
      {&cubic, json::json_pointer("/bounds/x_min_mm"), -1e308, "bounds.x_min_mm"},
      {&cubic, json::json_pointer("/bounds/y_max_mm"), 1e308, "bounds.y_max_mm"},
      {&cubic, json::json_pointer("/bounds/x_min_mm"), 5000, "bounds"},  // min above max
      {&spline, json::json_pointer("/bspline/weights_um/2/3"), 1e300,
       "bspline.weights_um[2][3] = 1e+300"},
      {&spline, json::json_pointer("/bounds/x_max_mm"), 1e308, "bounds.x_max_mm"}};
  for (const Case& c : cases) {
    json j = *c.base;
    j[c.at] = c.value;
    const std::string e = ErrorOf(j);
    EXPECT_EQ(e.rfind("surface file 's.json': ", 0), 0u) << c.field << ": " << e;
    EXPECT_NE(e.find(c.field), std::string::npos) << e;
  }
  for (const json& version : {json(1.5), json("1"), json(99)}) {
    json j = cubic;
    j["schema_version"] = version;
    EXPECT_NE(ErrorOf(j).find("schema_version"), std::string::npos) << version;
  }
}

// The ranges are what keeps an evaluation finite: cubic surfaces at the extremes (coefficients
// +-kMaxSurfaceCoefficientUm, the smallest half range, centres at the table's edge) evaluate to
// finite numbers anywhere within +-kMaxCoordinateMm; and such a surface passes CheckSurface.
TEST(SurfaceInputs, EvaluationsAreFiniteWithinTheRanges) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int rep = 0; rep < 2000; ++rep) {
    Surface s;
    s.method = Method::kCubic;
    s.bounds = {-kMaxCoordinateMm, kMaxCoordinateMm, -kMaxCoordinateMm, kMaxCoordinateMm};
    CubicSurface& c = s.cubic;
    c.x_center_mm = rep % 2 ? kMaxCoordinateMm : kMaxCoordinateMm * u(rng);
    c.y_center_mm = rep % 3 ? -kMaxCoordinateMm : kMaxCoordinateMm * u(rng);
    c.x_half_range_mm =
        rep % 5 ? kSamePositionMm : kSamePositionMm + kMaxCoordinateMm * std::abs(u(rng));
    c.y_half_range_mm = kSamePositionMm;
    for (double& b : c.b)
      b = rep % 7 ? kMaxSurfaceCoefficientUm * (u(rng) > 0 ? 1 : -1)
                  : kMaxSurfaceCoefficientUm * u(rng);
    ASSERT_NO_THROW(CheckSurface(s, "test"));
    const double x = rep % 11 ? -kMaxCoordinateMm : kMaxCoordinateMm * u(rng);
    const double y = kMaxCoordinateMm * u(rng);
    ASSERT_TRUE(std::isfinite(s.Evaluate(x, y))) << rep;
  }
}

// A fitted surface passes the checks its file is read with (what fit writes, predict reads).
TEST(SurfaceInputs, AFitPassesTheReadChecks) {
  for (Method m : {Method::kCubic, Method::kBspline}) {
    synthetic::SyntheticOptions o;
    o.nx = 100;
    o.ny = 100;  // 10000 points, the limit
    o.length_x_mm = kMaxCoordinateMm;
    const SurfaceFit f = FitSurface(synthetic::SyntheticPoints(o), {m, 1});
    EXPECT_NO_THROW(CheckSurface(f.surface, "test"));
  }
}

TEST(SurfaceInputs, AxisNameIsAnNcIdentifier) {
  synthetic::SyntheticOptions o;
  const Surface s = FitSurface(synthetic::SyntheticPoints(o), {Method::kCubic, 3}).surface;
  for (const char* bad :
       {"1", "_", "", "X Y", "1X", "X-1", "\xC3\x84", "XXXXXXXXXXXXXXXXXXXXXXXXXXXXXXXXX"}) {
    AxisLineOptions lo;
    lo.axis = bad;
    EXPECT_THROW(FitAxisLine(s, lo), InputError) << bad;
  }
  for (const char* good : {"X", "Z1", "X_2", "AX3"}) {
    AxisLineOptions lo;
    lo.axis = good;
    EXPECT_NO_THROW(FitAxisLine(s, lo)) << good;
  }
}

TEST(SurfaceInputs, SyntheticGridWithinThePointsLimit) {
  synthetic::SyntheticOptions o;
  o.nx = 200;
  o.ny = 200;
  EXPECT_THROW(synthetic::SyntheticPoints(o), InputError);
  o.nx = 100;
  o.ny = 101;
  EXPECT_THROW(synthetic::SyntheticPoints(o), InputError);
  o.ny = 100;
  EXPECT_EQ(synthetic::SyntheticPoints(o).size(), kMaxPoints);
}

TEST(SurfaceInputs, NearestSampleNeedsAFiniteTime) {
  const std::vector<double> t{0, 10, 20};
  EXPECT_THROW(NearestSample(t, NAN), InputError);
  EXPECT_THROW(NearestSample(t, INFINITY), InputError);
  EXPECT_EQ(NearestSample(t, 14), 1u);
}

}  // namespace
}  // namespace whirl::surface
