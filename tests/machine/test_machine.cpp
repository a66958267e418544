// The field machine's day logs as drift run files (machine/instruments.h CheckRingLog, what
// `whirl machine sensors` writes): the displacement channel is the check ring's error since
// power-on plus the sensor's noise, the files round-trip through the drift format, and a drift
// model fitted on production days follows a further day. (The machine itself: test_network,
// test_sensors, test_day; the evaluation of both halves: tests/machine_eval.)
#include <gtest/gtest.h>

#include <cmath>

#include "drift/fit.h"
#include "drift/model.h"
#include "drift/run_file.h"
#include "machine/instruments.h"
#include "machine/scenarios.h"
#include "machine/truth.h"

namespace whirl::machine {
namespace {

MachineWorld SensorsWorld() {
  CalendarSpec c;
  c.warmup_speeds_m_min = {180};
  c.laser_tests = 0;
  c.past_days = 3;
  c.test_days = 1;
  return BuildMachineWorld(DefaultFieldMachine(), FindMachineScenario("production"), 4, 0, c);
}

std::vector<int> HistoryDays(const MachineWorld& w, DayRole role) {
  std::vector<int> days;
  for (const DayPlan& p : w.timeline.days())
    if (p.day < 0 && p.role == role) days.push_back(p.day);
  return days;
}

// Without noise the channel is m(t, z_probe) - m(t_0, z_probe) at every row (the record's zero
// taken off); with noise it scatters about that by the noise.
TEST(CheckRingLog, TheChannelIsTheErrorSincePowerOnAtTheRing) {
  const MachineWorld w = SensorsWorld();
  const int day = HistoryDays(w, DayRole::kHistory).front();
  const drift::Run exact = CheckRingLog(w.timeline, day, 60, 150, 0.0, 7);
  ASSERT_EQ(exact.error_names, std::vector<std::string>{"offset_um"});
  ASSERT_GT(exact.samples(), 100);
  EXPECT_NEAR(exact.time_min.front(), w.timeline.Day(day).power_on_min(),
              10.0 / 60);  // since 00:00
  const double t0 = day * 1440.0 + exact.time_min.front();
  const double m0 = TrueError(w.timeline, t0, 150).total_um();
  double moved = 0;
  for (int k = 0; k < exact.samples(); k += 17) {
    const double t = day * 1440.0 + exact.time_min[static_cast<std::size_t>(k)];
    const double m = TrueError(w.timeline, t, 150).total_um() - m0;
    EXPECT_NEAR(exact.error_um(k, 0), m, 1e-9) << "row " << k;
    moved = std::max(moved, std::abs(m));
  }
  EXPECT_GT(moved, 3.0);  // the machine does drift over the day
  const drift::Run noisy = CheckRingLog(w.timeline, day, 60, 150, 0.5, 7);
  const Eigen::VectorXd d = noisy.error_um.col(0) - exact.error_um.col(0);
  const double mean = d.mean();
  const double sd = std::sqrt((d.array() - mean).square().sum() / (d.size() - 1));
  EXPECT_NEAR(sd, 0.5, 0.1);
  EXPECT_EQ(noisy.temperature_C, exact.temperature_C);  // the same log, only the channel differs
}

// The files round-trip, and `whirl drift fit`'s regression on the sensors, fitted on two
// production days, explains part of the channel on them (in-sample RMS error below the channel's
// spread about its mean, on the run-start zero of the drift model): the files carry what a drift
// model reads. How well sensor models carry over to
// other days is the machine evaluation's question (tests/machine_eval, docs).
TEST(CheckRingLog, RoundTripsThroughTheDriftFormatAndFits) {
  const MachineWorld w = SensorsWorld();
  std::vector<drift::Run> days;
  for (int d : HistoryDays(w, DayRole::kHistory)) {
    drift::Run run = CheckRingLog(w.timeline, d, 60, 150, 0.5, 100 + d);
    run.state = drift::RunState::kCutting;
    days.push_back(
        drift::ParseRun(drift::FormatRun(run, {"test"}), "day.csv", drift::RunState::kCutting));
    const drift::Run& back = days.back();
    ASSERT_EQ(back.sensor_names, run.sensor_names);
    ASSERT_EQ(back.other_names, run.other_names);
    EXPECT_LT((back.temperature_C - run.temperature_C).cwiseAbs().maxCoeff(), 1e-6);
    EXPECT_LT((back.error_um - run.error_um).cwiseAbs().maxCoeff(), 1e-6);
  }
  ASSERT_EQ(days.size(), 3u);
  drift::FitOptions fo;
  fo.threads = 1;
  fo.candidates = drift::Candidates::kSensors;
  const drift::DriftModel model = drift::FitDriftModel({days[0], days[1]}, "offset_um", fo).model;
  for (int d : {0, 1}) {
    const drift::RunPrediction p = drift::PredictRun(model, days[static_cast<std::size_t>(d)]);
    const Eigen::ArrayXd m = p.measured_um.array();
    const double spread = std::sqrt((m - m.mean()).square().mean());
    const double error = std::sqrt((p.predicted_um.array() - m).square().mean());
    EXPECT_GT(spread, 3.0) << "day " << d;
    EXPECT_LT(error, spread) << "day " << d;
  }
}

}  // namespace
}  // namespace whirl::machine
