// Per-point models from the drift module (surface/drift_adapter.h): MLR per position-tagged error
// column on a training run, predicted on another run, then a surface at one moment.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "drift/fit.h"
#include "drift/run_file.h"
#include "surface/drift_adapter.h"
#include "surface/surface.h"

namespace whirl::surface {
namespace {

// Error at (x, y): a(x, y) dT1 + b(x, y) dT2 with a, b linear in x and y (a plane at any moment).
double Field(double x, double y, double dt1, double dt2) {
  return (1 + x / 400) * dt1 + (0.5 + y / 300) * dt2;
}

std::string RunText(double tau1, double tau2, double gain) {
  std::ostringstream s;
  s.precision(17);
  s << "time_min,t1_C,t2_C";
  const std::vector<double> xs{0, 200, 400, 600}, ys{0, 100, 200, 300};
  for (double y : ys)
    for (double x : xs) s << ",p_x" << x << "_y" << y << "_um";
  s << "\n";
  for (int k = 0; k <= 80; ++k) {
    const double t = 5.0 * k;
    const double dt1 = gain * 8 * (1 - std::exp(-t / tau1)), dt2 = 3 * (1 - std::exp(-t / tau2));
    s << t << "," << 20 + dt1 << "," << 21 + dt2;
    for (double y : ys)
      for (double x : xs) s << "," << Field(x, y, dt1, dt2);
    s << "\n";
  }
  return s.str();
}

TEST(DriftAdapter, MlrPerPointThenSurface) {
  const drift::Run train =
      drift::ParseRun(RunText(30, 120, 1.0), "train.csv", drift::RunState::kCutting);
  const drift::Run target =
      drift::ParseRun(RunText(50, 90, 0.7), "target.csv", drift::RunState::kCutting);
  drift::FitOptions options;
  options.sensors = {"t1_C", "t2_C"};  // given: the field is exact in them
  DriftPointNotes notes;
  const auto points = PointColumnsFromHeader(target.error_names, "target.csv");
  ASSERT_EQ(points.size(), 16u);
  const PointPredictions p =
      PredictAllPoints(points, DriftPointModel({train}, target, options, &notes), 2);
  ASSERT_EQ(p.predicted_um.rows(), target.samples());
  for (std::size_t k = 0; k < points.size(); ++k)
    for (int s = 0; s < target.samples(); s += 10)
      EXPECT_NEAR(p.predicted_um(s, static_cast<Eigen::Index>(k)),
                  target.error_um(s, target.ErrorIndex(points[k].column)), 1e-6);
  EXPECT_EQ(notes.by_column.size(), 16u);
  const std::size_t k = NearestSample(target.time_min, 100);
  const double dt1 = 0.7 * 8 * (1 - std::exp(-100.0 / 50)), dt2 = 3 * (1 - std::exp(-100.0 / 90));
  const SurfaceFit fit = FitSurface(PointsAtSample(p, k), {Method::kCubic, 3});
  EXPECT_NEAR(fit.surface.Evaluate(333, 77), Field(333, 77, dt1, dt2), 1e-5);
}

TEST(DriftAdapter, SeedSelectionRunsPerPoint) {
  const drift::Run train =
      drift::ParseRun(RunText(30, 120, 1.0), "train.csv", drift::RunState::kCutting);
  const auto points = PointColumnsFromHeader(train.error_names, "train.csv");
  DriftPointNotes notes;
  const PointPredictions p =
      PredictAllPoints(points, DriftPointModel({train}, train, drift::FitOptions{}, &notes), 2);
  EXPECT_EQ(p.predicted_um.cols(), 16);
  EXPECT_TRUE(p.predicted_um.allFinite());
  for (const auto& [column, note] : notes.by_column)
    EXPECT_NE(note.find("_C"), std::string::npos) << column << ": " << note;
}

}  // namespace
}  // namespace whirl::surface
