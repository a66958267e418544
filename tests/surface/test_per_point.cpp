// Per-point models over the table (surface/per_point.h) with closed-form stand-in models.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/csv.h"
#include "core/error.h"
#include "surface/per_point.h"
#include "surface/surface.h"
#include "support/scratch_dir.h"

namespace whirl::surface {
namespace {

TEST(PerPoint, PositionsFromColumnNames) {
  EXPECT_EQ(PositionFromColumnName("p3_x400_y250_um"), std::make_pair(400.0, 250.0));
  EXPECT_EQ(PositionFromColumnName("e_x-50.5_y0_um"), std::make_pair(-50.5, 0.0));
  EXPECT_FALSE(PositionFromColumnName("ch1_um"));
  EXPECT_FALSE(PositionFromColumnName("p_x1_y2_C"));
  EXPECT_FALSE(PositionFromColumnName("p_x1e3_y2_um"));
  const auto cols = PointColumnsFromHeader({"time_min", "t1_C", "a_x0_y0_um", "ch9_um"}, "r.csv");
  ASSERT_EQ(cols.size(), 1u);
  EXPECT_EQ(cols[0].column, "a_x0_y0_um");
  EXPECT_THROW(PointColumnsFromHeader({"time_min", "ch1_um"}, "r.csv"), InputError);
}

TEST(PerPoint, ManifestIsCheckedAgainstTheRun) {
  const auto path = whirl::test::ScratchDir() / "whirl_surface_manifest.json";
  auto write = [&](const std::string& text) { std::ofstream(path) << text; };
  const std::vector<std::string> header{"time_min", "t1_C", "e1_um", "e2_um"};
  write(R"({"schema": "whirl.surface_manifest", "schema_version": 1, "points": [
           {"column": "e1_um", "x_mm": 0, "y_mm": 0}, {"column": "e2_um", "x_mm": 100, "y_mm": 5}]})");
  const auto p = ReadPointManifest(path, header);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1].x_mm, 100);
  write(R"({"schema": "whirl.surface_manifest", "schema_version": 1, "points": [
           {"column": "e3_um", "x_mm": 0, "y_mm": 0}]})");
  EXPECT_THROW(ReadPointManifest(path, header), InputError);  // no such column
  write(R"({"schema": "whirl.surface_manifest", "schema_version": 1, "points": [
           {"column": "t1_C", "x_mm": 0, "y_mm": 0}]})");
  EXPECT_THROW(ReadPointManifest(path, header), InputError);  // not an error column
  write(R"({"schema": "whirl.surface_manifest", "schema_version": 1, "points": [
           {"column": "e1_um", "x_mm": 0, "y_mm": 0}, {"column": "e1_um", "x_mm": 1, "y_mm": 0}]})");
  EXPECT_THROW(ReadPointManifest(path, header), InputError);  // twice
  std::filesystem::remove(path);
}

// Error at (x, y) and time t: a(x, y) dT1(t) + b(x, y) dT2(t), a and b linear in x and y, so at
// any moment the field is a plane and the cubic through the P per-point predictions reproduces it.
TEST(PerPoint, PredictionsBecomeASurfaceAtAnyMoment) {
  auto dt1 = [](double t) { return 8 * (1 - std::exp(-t / 30)); };
  auto dt2 = [](double t) { return 3 * (1 - std::exp(-t / 120)); };
  auto field = [&](double x, double y, double t) {
    return (1 + x / 400) * dt1(t) + (0.5 + y / 300) * dt2(t);
  };
  std::vector<double> times;
  for (int k = 0; k <= 60; ++k) times.push_back(5.0 * k);
  std::vector<PointColumn> points;
  for (double y : {0.0, 100.0, 200.0, 300.0})  // 3 rows would leave the cubic rank 9
    for (double x : {0.0, 200.0, 400.0, 600.0})
      points.push_back(
          {"p_x" + std::to_string(int(x)) + "_y" + std::to_string(int(y)) + "_um", x, y});
  // The stand-in model "knows" the field: it returns the truth at its column's position.
  const PointModelFn model = [&](const std::string& column) {
    const auto xy = PositionFromColumnName(column);
    std::vector<double> e;
    for (double t : times) e.push_back(field(xy->first, xy->second, t));
    return e;
  };
  const PointPredictions p1 = PredictAllPoints(points, model, 1);
  const PointPredictions p4 = PredictAllPoints(points, model, 4);
  EXPECT_EQ(p1.predicted_um, p4.predicted_um);  // independent of the thread count
  const std::size_t k = NearestSample(times, 97);
  EXPECT_EQ(times[k], 95);
  const SurfaceFit fit = FitSurface(PointsAtSample(p1, k), {Method::kCubic, 3});
  EXPECT_NEAR(fit.surface.Evaluate(333, 77), field(333, 77, 95), 1e-9);
  const SurfaceFit spline = FitSurface(PointsAtSample(p1, k), {Method::kBspline, 2});
  EXPECT_NEAR(spline.surface.Evaluate(333, 77), field(333, 77, 95), 1e-9);
}

TEST(PerPoint, ModelsThatDisagreeOnLengthOrGiveNanAreRefused) {
  const std::vector<PointColumn> points{{"a_x0_y0_um", 0, 0}, {"b_x1_y0_um", 1, 0}};
  EXPECT_THROW(PredictAllPoints(points,
                                [](const std::string& c) {
                                  return std::vector<double>(c[0] == 'a' ? 3 : 4, 1.0);
                                }),
               InputError);
  EXPECT_THROW(PredictAllPoints(points,
                                [](const std::string&) {
                                  return std::vector<double>{1, NAN};
                                }),
               InputError);
  EXPECT_THROW(PredictAllPoints(points,
                                [](const std::string&) -> std::vector<double> {
                                  throw InputError("model failed");
                                }),
               InputError);  // a model's exception reaches the caller
}

}  // namespace
}  // namespace whirl::surface

namespace whirl::surface {
namespace {

TEST(PointsFile, LimitsAndMissingColumnsNameTheFileLineAndRule) {
  try {
    PointsFromTable(ParseCsv("x_mm,y_mm,error_um\n0,0,1\n0,200000,1\n", "p.csv"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.csv:3: column 'y_mm'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("beyond +-100000"), std::string::npos) << e.what();
  }
  EXPECT_THROW(PointsFromTable(ParseCsv("x_mm,error_um\n0,1\n", "p.csv")), InputError);
  std::string big = "x_mm,y_mm,error_um\n";
  for (std::size_t k = 0; k <= kMaxPoints; ++k) big += "0,0,0\n";
  EXPECT_THROW(PointsFromTable(ParseCsv(big, "big.csv")), InputError);
  EXPECT_EQ(OneLine("a\nb\rc\td"), "a b c d");
}

}  // namespace
}  // namespace whirl::surface
