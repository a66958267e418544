// The field world's optional parts of issue 41 (off by default): seasonal hall offsets (a closed
// form added to the hall), a shift-pattern change between training and test weeks, and a contact
// reading of each blank at clamping (the blank's own temperature, not the hall's).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/error.h"
#include "core/numbers.h"
#include "machine/instruments.h"
#include "machine/scenarios.h"
#include "machine/truth.h"

namespace whirl::machine {
namespace world_parts_test {

// The seasons add exactly A cos(2 pi (t / 1440 - peak) / 365.25) to the same hall, both kinds.
TEST(WorldParts, SeasonsAddTheirClosedFormToTheHall) {
  for (HallOptions o : {HallOptions::Conditioned(), HallOptions::Unconditioned(), HallOptions::Ramp()}) {
    const HallProfile plain(o, -60, 10, 9);
    o.seasonal_amplitude_k = 4;
    o.seasonal_peak_day = 30;
    const HallProfile season(o, -60, 10, 9);
    for (double t = -60 * 1440.0; t < 10 * 1440.0; t += 997) {
      const double expected = 4 * std::cos(2 * kPi * (t / 1440 - 30) / 365.25);
      ASSERT_NEAR(season.At(t) - plain.At(t), expected, 1e-9) << o.kind << " t " << t;
    }
  }
  HallOptions bad;
  bad.seasonal_amplitude_k = 20;
  EXPECT_THROW(HallProfile(bad, 0, 1, 1), InputError);
}

// Test days planned with another scenario's day rules: two shifts from day 0 on, the history keeps
// the scenario's one shift exactly.
TEST(WorldParts, AShiftChangeMovesOnlyTheTestDays) {
  const MachineScenario production = FindMachineScenario("production");
  CalendarSpec plain;
  plain.past_days = 3;
  plain.test_days = 3;
  CalendarSpec changed = plain;
  changed.test_day_options = FindMachineScenario("interrupted-starts").day;
  const auto a = PlanCalendar(production, 17, plain, 0.1);
  const auto b = PlanCalendar(production, 17, changed, 0.1);
  ASSERT_EQ(a.size(), b.size());
  int later = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i].day < 0) {
      EXPECT_EQ(a[i].power_off_min(), b[i].power_off_min()) << "day " << a[i].day;
      EXPECT_EQ(a[i].jobs.size(), b[i].jobs.size());
    } else {
      EXPECT_LE(a[i].power_off_min(), production.day.shift_end_min + production.day.late_end_min);
      later += b[i].power_off_min() > production.day.shift_end_min + production.day.late_end_min;
    }
  }
  EXPECT_GE(later, 2);  // the second shift is worked on the test days
}

// The contact reading follows the blank, stock offset included (the hall cannot), and adds a
// column without changing any other reading of the log.
TEST(WorldParts, TheContactReadingSeesTheStockOffset) {
  CalendarSpec cal;
  cal.past_days = 1;
  cal.test_days = 2;
  FieldMachineConfig c = DefaultFieldMachine();
  c.stock_offset_std_k = 3;
  const MachineScenario s = FindMachineScenario("production");
  const MachineWorld plain = BuildMachineWorld(c, s, 4, 0, cal);
  c.blank_contact_std_k = 0;
  const MachineWorld read = BuildMachineWorld(c, s, 4, 0, cal);
  int cuts = 0;
  double stock = 0;
  for (const DayPlan& plan : read.timeline.days()) {
    if (plan.day < 0) continue;
    const drift::Run with = ControlLog(read.timeline, plan.day, 5);
    const drift::Run without = ControlLog(plain.timeline, plan.day, 5);
    ASSERT_EQ(with.sensor_names.back(), "blank_contact_C");
    EXPECT_EQ(with.temperature_C.leftCols(without.temperature_C.cols()), without.temperature_C);
    const int col = with.SensorIndex("blank_contact_C");
    for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
      const double start = plan.day * 1440.0 + plan.jobs[static_cast<std::size_t>(j)].cut_start_min;
      int k = 0;
      while (k + 1 < with.samples() && with.time_min[static_cast<std::size_t>(k + 1)] <= start) ++k;
      const CutHall h = HallDuringCut(read.timeline, {plan.day, j});
      // Read at clamping, 20-40 min before the cut: the blank's lag (45 min) moves it little.
      EXPECT_NEAR(with.temperature_C(k, col), h.start_c, 0.3) << "day " << plan.day << " job " << j;
      stock += std::abs(h.start_c - read.timeline.hall().At(start));
      ++cuts;
    }
  }
  EXPECT_GE(cuts, 4);
  EXPECT_GT(stock / cuts, 1.0);  // the stock really is off the hall
}

}  // namespace world_parts_test
}  // namespace whirl::machine
