// The blank's temperature at the cut start (machine/truth.h HallDuringCut), issue 41's world
// parameters: a lag from each blank's diameter, tau = rho c D / (4 h), checked against an
// independent quadrature of the exponential kernel over the hall; and stock whose temperature is
// independent of the hall (N(0, sd) per screw).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "machine/scenarios.h"
#include "core/error.h"
#include "machine/truth.h"

namespace whirl::machine {
namespace blank_test {

MachineScenario SmoothHall(double amplitude_k) {
  MachineScenario s = FindMachineScenario("production");
  s.hall.amplitude_k = amplitude_k;
  s.hall.ou_std_k = s.hall.day_offset_std_k = 0;
  s.hall.door_events_per_day = 0;
  return s;
}

// The first-order lag of the hall at t0: int_0^inf exp(-s / tau) / tau T(t0 - s) ds, trapezoid
// with tau / 400 over 14 tau.
double LaggedHall(const HallProfile& hall, double t0, double tau) {
  const double h = tau / 400;
  double sum = 0;
  for (int i = 0; i <= 14 * 400; ++i) {
    const double s = i * h, w = (i == 0 || i == 14 * 400) ? 0.5 : 1.0;
    sum += w * std::exp(-s / tau) / tau * hall.At(t0 - s) * h;
  }
  return sum;
}

TEST(Blank, ItsLagFollowsFromItsDiameter) {
  CalendarSpec cal;
  cal.past_days = 1;
  cal.test_days = 2;
  for (double h : {6.0, 12.0}) {
    FieldMachineConfig c = DefaultFieldMachine();
    c.blank_h_w_m2k = h;
    const MachineWorld w = BuildMachineWorld(c, SmoothHall(2.5), 3, 0, cal);
    int checked = 0;
    for (const DayPlan& plan : w.timeline.days()) {
      if (plan.day < 0) continue;
      for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
        const Job& job = plan.jobs[static_cast<std::size_t>(j)];
        const double d_m = job.screw.process.diameter_mm / 1000;
        const double tau_min = c.steel_density * c.steel_heat * d_m / (4 * h) / 60;
        const double start = plan.day * 1440.0 + job.cut_start_min;
        EXPECT_NEAR(HallDuringCut(w.timeline, {plan.day, j}).start_c,
                    LaggedHall(w.timeline.hall(), start, tau_min), 0.02)
            << "h " << h << " D " << job.screw.process.diameter_mm << " tau " << tau_min;
        ++checked;
      }
    }
    EXPECT_GE(checked, 4);
  }
}

TEST(Blank, StockFromTheStoreIsIndependentOfTheHall) {
  CalendarSpec cal;
  cal.past_days = 1;
  cal.test_days = 3;
  for (double sd : {0.0, 3.0}) {
    FieldMachineConfig c = DefaultFieldMachine();
    c.stock_offset_std_k = sd;
    std::vector<double> offsets;
    for (int i = 0; i < 4; ++i) {
      const MachineWorld w = BuildMachineWorld(c, SmoothHall(0), 5, i, cal);
      for (const DayPlan& plan : w.timeline.days())
        for (int j = 0; plan.day >= 0 && j < static_cast<int>(plan.jobs.size()); ++j)
          offsets.push_back(HallDuringCut(w.timeline, {plan.day, j}).start_c - 20.0);
    }
    ASSERT_GE(offsets.size(), 30u);
    double mean = 0, sq = 0;
    for (double o : offsets) mean += o / offsets.size();
    for (double o : offsets) sq += (o - mean) * (o - mean) / (offsets.size() - 1);
    if (sd == 0) {
      for (double o : offsets) EXPECT_NEAR(o, 0.0, 1e-9);
    } else {
      EXPECT_NEAR(std::sqrt(sq), sd, 0.35 * sd) << offsets.size() << " screws";
      EXPECT_NEAR(mean, 0.0, 4 * sd / std::sqrt(offsets.size()));
    }
  }
}

TEST(Blank, ParametersOutsideTheirRangeAreRefused) {
  FieldMachineConfig c = DefaultFieldMachine();
  c.blank_h_w_m2k = -1;
  EXPECT_THROW(c.Validate("t"), InputError);
  c = DefaultFieldMachine();
  c.stock_offset_std_k = 11;
  EXPECT_THROW(c.Validate("t"), InputError);
}

}  // namespace blank_test
}  // namespace whirl::machine
