// The shop day (src/lab/machine/day.h) and the calendar (scenarios.h): ordered events, cut lengths,
// breaks, start types, disjoint day seeds.
#include <gtest/gtest.h>

#include <set>

#include "core/error.h"
#include "machine/scenarios.h"

namespace whirl::machine {
namespace {

bool InBreak(const DayOptions& o, double t) {
  for (const Break& b : o.breaks)
    if (t > b.clock_min + 1e-9 && t < b.clock_min + b.duration_min - 1e-9) return true;
  return false;
}

void CheckDay(const DayPlan& plan, const DayOptions& o) {
  ASSERT_GE(plan.events.size(), 2u);
  EXPECT_EQ(plan.events.front().kind, EventKind::kPowerOn);
  EXPECT_EQ(plan.events.back().kind, EventKind::kPowerOff);
  for (std::size_t i = 1; i < plan.events.size(); ++i) {
    EXPECT_LE(plan.events[i - 1].end_min, plan.events[i].start_min + 1e-9) << i;
    EXPECT_LE(plan.events[i].start_min, plan.events[i].end_min);
  }
  for (const ScheduleEvent& e : plan.events) {
    if (e.kind != EventKind::kCut) continue;
    const Job& job = plan.jobs[e.job];
    EXPECT_NEAR(e.end_min - e.start_min,
                job.screw.thread_length_mm / job.kinematics.axial_feed_mm_min, 1e-9);
    EXPECT_FALSE(InBreak(o, e.start_min)) << "a cut starts inside a break at " << e.start_min;
    EXPECT_LE(e.end_min, o.shift_end_min + o.late_end_min + 1e-9);
  }
  // Every break either lies inside a cut (the cut runs through it) or is an event of its own.
  for (const Break& b : o.breaks) {
    if (b.clock_min >= plan.power_off_min()) continue;
    bool covered = false;
    for (const ScheduleEvent& e : plan.events)
      covered |= (e.kind == EventKind::kBreak && std::abs(e.end_min - b.clock_min - b.duration_min) < 1e-9) ||
                 ((e.kind == EventKind::kCut || e.kind == EventKind::kWarmupIdle) &&
                  e.start_min <= b.clock_min && e.end_min > b.clock_min);
    EXPECT_TRUE(covered) << "break at " << b.clock_min << " on day " << plan.day;
  }
}

TEST(ShopDay, EventsOrderedCutsTimedBreaksKept) {
  for (const char* name : {"production", "duty-changes", "interrupted-starts", "constant-duty"}) {
    const MachineScenario& s = FindMachineScenario(name);
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
      const DayPlan plan = PlanDay(s.day, 7 * static_cast<int>(seed), seed, s.jobs, 0.1);
      CheckDay(plan, s.day);
      if (s.day.one_cut_per_day) {
        EXPECT_EQ(plan.jobs.size(), 1u);
      } else {
        EXPECT_GE(plan.jobs.size(), 2u) << name;
      }
    }
  }
}

TEST(ShopDay, StartTypesFollowThePause) {
  const MachineScenario& s = FindMachineScenario("interrupted-starts");
  CalendarSpec spec;
  spec.test_days = 4;
  std::vector<DayPlan> days = PlanCalendar(s, 99, spec, 0.1);
  std::set<StartType> seen;
  for (const DayPlan& d : days) {
    for (std::size_t j = 0; j < d.jobs.size(); ++j) {
      const Job& job = d.jobs[j];
      seen.insert(job.start_type);
      if (j == 0) {  // cold after >= 8 h off; a late second shift can leave less
        EXPECT_TRUE(job.start_type == StartType::kCold || job.start_type == StartType::kLongPause);
        continue;
      }
      const double p = job.pause_before_min;
      const StartType want = p <= 45 ? StartType::kWarm
                             : p <= 180 ? StartType::kInterrupted : StartType::kLongPause;
      EXPECT_EQ(job.start_type, want) << "pause " << p;
    }
  }
  EXPECT_TRUE(seen.count(StartType::kCold) && seen.count(StartType::kWarm) &&
              seen.count(StartType::kInterrupted));
}

TEST(ShopDay, SetupMeetingABreakIsExtended) {
  DayOptions o;
  o.breaks = {{380, 30}};
  o.setup_min_lo = o.setup_min_hi = 40;  // 06:00 + 40 min meets the 06:20 break
  const JobMix mix;
  const DayPlan plan = PlanDay(o, 0, 5, mix, 0);
  ASSERT_GE(plan.events.size(), 4u);
  EXPECT_EQ(plan.events[1].kind, EventKind::kSetup);
  EXPECT_DOUBLE_EQ(plan.events[1].end_min, 380);
  EXPECT_EQ(plan.events[2].kind, EventKind::kBreak);
  EXPECT_DOUBLE_EQ(plan.events[2].end_min, 410);
  EXPECT_EQ(plan.events[3].kind, EventKind::kSetup);
  EXPECT_DOUBLE_EQ(plan.events[3].end_min, 430);  // 20 min left after the break
}

// The legacy evaluation's seeds DaySeed(m, k) and DaySeed(m, 100 + r) collide at k = 100; the
// signed day index keeps history and test days apart for any count.
TEST(ShopDay, HistoryAndTestDaySeedsAreDisjoint) {
  std::set<std::uint64_t> seeds;
  for (int m = 0; m < 50; ++m)
    for (int d = -200; d < 200; ++d) seeds.insert(DaySeed(MachineSeed(1, m), d));
  EXPECT_EQ(seeds.size(), 50u * 400u);
  EXPECT_THROW(DaySeed(1, 1 << 20), InputError);
}

TEST(Scenarios, SelectionAndCalendar) {
  EXPECT_EQ(SelectMachineScenarios("all").size(), 6u);
  EXPECT_THROW(SelectMachineScenarios("legacy"), InputError);  // the retired world
  EXPECT_EQ(SelectMachineScenarios("production,linear-scale").size(), 2u);
  try {
    SelectMachineScenarios("production,bogus");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--scenarios"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("bogus"), std::string::npos);
  }
  const std::vector<DayPlan> days =
      PlanCalendar(FindMachineScenario("production"), 3, CalendarSpec{}, 0.1);
  for (const DayPlan& d : days) {
    EXPECT_TRUE(IsWorkday(d.day));
    EXPECT_EQ(d.role == DayRole::kTest, d.day >= 0);
  }
}

}  // namespace
}  // namespace whirl::machine
