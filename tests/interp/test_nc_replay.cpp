// The NC programs replayed as a control would run them (tests/interp/nc_replay.h): the applied
// compensation follows the curve along the travel, and the control ends as it was found, after a
// complete cut, after an abort plus the reset program, and after a rerun without a reset.
#include <gtest/gtest.h>

#include <iterator>
#include <random>
#include <regex>

#include "core/error.h"
#include "fit/arctan_curve.h"
#include "interp/machine_profile.h"
#include "interp/nc_replay.h"
#include "interp/sinumerik.h"

namespace whirl::interp {
namespace {

struct CutSetup {
  fit::ArctanCurve curve;
  double feed_mm_s = 0;
  double thread_mm = 0;
  PlanOptions options;
};

CutSetup RandomSetup(std::mt19937& rng) {
  std::uniform_real_distribution<double> ul(5.0, 60.0), uts(120.0, 600.0), ufeed(0.4, 1.2),
      uthread(500.0, 3000.0), upos(-2000.0, 2000.0), utol(0.2, 1.0);
  CutSetup s;
  s.curve = fit::ArctanCurve::FromFeatures({ul(rng), uts(rng)}, fit::kDefaultShapeK,
                                           fit::kDefaultTimeExponent);
  s.feed_mm_s = ufeed(rng);
  s.thread_mm = uthread(rng);
  PlanOptions& o = s.options;
  o.tolerance_um = utol(rng);
  o.start_position_mm = upos(rng);
  o.machine_offset_mm = upos(rng);
  o.direction = rng() % 2 ? 1 : -1;
  o.control_dk = rng() % 2 ? ControlDk::kAdded : ControlDk::kSubtracted;
  o.sign = ExpectedSign(o.direction, o.control_dk);
  o.md32760 = kMd32760Max;
  o.sync_id_first = 100 + static_cast<int>(rng() % 50);
  o.sync_id_last = o.sync_id_first + 60;
  o.save_r_first = 10 + static_cast<int>(rng() % 80);
  return s;
}

// The axis `before_mm` before the thread start in the direction of travel (negative: past it).
double Park(const PlanOptions& o, double before_mm) {
  return AxisPositionMm(o, 1.0, 0.0) - o.direction * before_mm;
}

// What the machine builder left on the control before whirl's program runs.
replay::Replay FoundState(const PlanOptions& o, std::mt19937& rng) {
  replay::Replay r;
  r.axis = o.axis;
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  r.control.abs_value_mm = 0.004 * u(rng);
  r.control.slope = 2e-5 * u(rng);
  r.control.ref_position_mm = 500 * u(rng);
  for (int k = 0; k < 4; ++k) r.control.r[o.save_r_first + k] = 123.0 + k;  // stale values
  r.control.r[o.save_r_first + 3] = 0;  // no whirl compensation active
  r.axis_mm = Park(o, 5.0);             // parked 5 mm before the thread start
  replay::SyncAction builders;          // the machine builder's own action, outside whirl's range
  builders.id = o.sync_id_first - 1;
  builders.mode = replay::SyncAction::Mode::kWhen;
  builders.lhs = "$AA_IM[" + o.axis + "]";
  builders.op = ">=";
  builders.rhs = "1000000000";
  r.actions[builders.id] = builders;
  replay::SyncAction stale;  // a leftover inside whirl's range
  stale.id = o.sync_id_last;
  stale.mode = replay::SyncAction::Mode::kEveryCycle;
  stale.writes = {{"ABS", "0.5"}};
  r.actions[stale.id] = stale;
  return r;
}

void ExpectUnchanged(const replay::Control& now, const replay::Control& before) {
  EXPECT_EQ(now.abs_value_mm, before.abs_value_mm);
  EXPECT_EQ(now.slope, before.slope);
  EXPECT_EQ(now.ref_position_mm, before.ref_position_mm);
}

TEST(NcReplay, CompensationFollowsTheCurveAndTheControlEndsAsFound) {
  std::mt19937 rng(1801);
  for (int trial = 0; trial < 40; ++trial) {
    const CutSetup s = RandomSetup(rng);
    const CompensationPlan plan = BuildPlan(s.curve, s.feed_mm_s, s.thread_mm, s.options);
    replay::Replay r = FoundState(s.options, rng);
    const replay::Control before = r.control;
    ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan)));
    ASSERT_FALSE(HasFailure());
    EXPECT_EQ(r.actions.count(s.options.sync_id_first - 1), 1u) << "builder's action kept";
    const double sgn = SignFactor(s.options.sign);
    const double t_end = s.thread_mm / s.feed_mm_s;
    double worst_um = 0;
    const int cycles = 20000;
    for (int i = 0; i <= cycles; ++i) {
      const double t = t_end * i / cycles;
      const double p = AxisPositionMm(s.options, s.feed_mm_s, t);
      r.Cycle(p);
      // From the first cycle past the thread start (its trigger is printed to 0.1 um, so at
      // t = 0 exactly the axis may stand a hair before it and the found values still apply).
      if (i == 0) continue;
      if (i == cycles) break;
      worst_um =
          std::max(worst_um, std::abs(r.control.DkMm(p) * 1000.0 / sgn - s.curve.ElongationUm(t)));
    }
    EXPECT_LE(worst_um, s.options.tolerance_um) << "trial " << trial;
    r.Cycle(AxisPositionMm(s.options, s.feed_mm_s, t_end) + s.options.direction * 0.5);  // run-out
    ExpectUnchanged(r.control, before);
    EXPECT_EQ(r.control.r[s.options.save_r_first + 3], 0.0) << "marker cleared";
  }
}

TEST(NcReplay, AbortThenResetAndRerunWithoutResetRestoreTheFoundValues) {
  std::mt19937 rng(1802);
  for (int trial = 0; trial < 20; ++trial) {
    const CutSetup s = RandomSetup(rng);
    const CompensationPlan plan = BuildPlan(s.curve, s.feed_mm_s, s.thread_mm, s.options);
    const std::string nc = FormatNcProgram(plan);
    replay::Replay r = FoundState(s.options, rng);
    const replay::Control before = r.control;
    const double t_end = s.thread_mm / s.feed_mm_s;
    auto cut_to = [&](double fraction) {
      for (int i = 0; i <= 2000; ++i)
        r.Cycle(AxisPositionMm(s.options, s.feed_mm_s, t_end * fraction * i / 2000));
      if (fraction >= 1)
        r.Cycle(AxisPositionMm(s.options, s.feed_mm_s, t_end) + s.options.direction);
    };
    const double park = Park(s.options, 20.0);
    // Aborted halfway, then a rerun of the whole program without the reset program, the axis
    // moved back before the thread start first (from mid-thread the program refuses).
    ASSERT_TRUE(r.RunProgram(nc));
    cut_to(0.5);
    r.EndProgram();
    EXPECT_NE(r.control.abs_value_mm, before.abs_value_mm);
    r.Cycle(park);
    ASSERT_TRUE(r.RunProgram(nc));
    cut_to(1.0);
    r.EndProgram();
    ExpectUnchanged(r.control, before);
    // Aborted again, then the reset program.
    r.Cycle(park);
    ASSERT_TRUE(r.RunProgram(nc));
    cut_to(0.3);
    r.EndProgram();
    ASSERT_TRUE(r.RunProgram(FormatNcResetProgram(plan.options)));
    ExpectUnchanged(r.control, before);
    // The reset program on a control where nothing is active changes nothing.
    ASSERT_TRUE(r.RunProgram(FormatNcResetProgram(plan.options)));
    ExpectUnchanged(r.control, before);
    // The axis stops a hair before the thread end (no run-out): the reset program called after
    // the cutting block, as documented, restores.
    r.Cycle(park);
    ASSERT_TRUE(r.RunProgram(nc));
    for (int i = 0; i <= 2000; ++i)
      r.Cycle(AxisPositionMm(s.options, s.feed_mm_s, t_end * i / 2000) -
              s.options.direction * 1e-3);
    r.EndProgram();
    r.RunProgram(FormatNcResetProgram(plan.options));
    ExpectUnchanged(r.control, before);
  }
}

TEST(NcReplay, TooFewIdsInTheRangeIsAnError) {
  std::mt19937 rng(1803);
  CutSetup s = RandomSetup(rng);
  const CompensationPlan plan = BuildPlan(s.curve, s.feed_mm_s, s.thread_mm, s.options);
  CompensationPlan narrow = plan;
  narrow.options.sync_id_last =
      narrow.options.sync_id_first + static_cast<int>(plan.segments.size()) - 1;
  EXPECT_THROW(FormatNcProgram(narrow), InputError);
  narrow.options.sync_id_last += 1;  // exactly enough: every segment + the restore
  EXPECT_NO_THROW(FormatNcProgram(narrow));
}

// Every action is triggered by the position alone: called with the axis at or past the first
// trigger (the thread start), e.g. a rerun from mid-thread or from the previous cut's end, all
// passed actions would fire in the first cycle. The program raises its alarm instead, before it
// changes anything: setting data, R parameters and the actions on the control stay as found.
TEST(NcReplay, CalledWithTheAxisPastTheFirstTriggerRefusesAndChangesNothing) {
  std::mt19937 rng(1804);
  for (int trial = 0; trial < 20; ++trial) {
    const CutSetup s = RandomSetup(rng);
    const PlanOptions& o = s.options;
    const CompensationPlan plan = BuildPlan(s.curve, s.feed_mm_s, s.thread_mm, o);
    const std::string nc = FormatNcProgram(plan);
    const double t_end = s.thread_mm / s.feed_mm_s;
    const double past[] = {plan.segments.front().sd43920_mm,  // exactly at the thread start
                           plan.segments.front().sd43920_mm + o.direction * 1e-4,
                           AxisPositionMm(o, s.feed_mm_s, 0.5 * t_end),  // rerun from mid-thread
                           AxisPositionMm(o, s.feed_mm_s, t_end),  // the previous cut's end
                           AxisPositionMm(o, s.feed_mm_s, t_end) + o.direction * 300.0};
    for (std::size_t k = 0; k < std::size(past); ++k) {
      replay::Replay r = FoundState(o, rng);
      r.axis_mm = past[k];
      if (k % 2) r.control.r[o.save_r_first + 3] = 1;  // also after an aborted run
      const replay::Replay before = r;
      EXPECT_FALSE(r.RunProgram(nc)) << "started at " << past[k];
      EXPECT_EQ(r.control.alarm, o.start_alarm);
      ExpectUnchanged(r.control, before.control);
      EXPECT_EQ(r.control.r, before.control.r) << "R parameters";
      EXPECT_EQ(r.control.ac_param, before.control.ac_param);
      ASSERT_EQ(r.actions.size(), before.actions.size()) << "an action added or cancelled";
      for (const auto& [id, a] : before.actions) EXPECT_EQ(r.actions.count(id), 1u) << id;
    }
    // A hair before the thread start the program runs, and no action fires before the axis moves.
    replay::Replay r = FoundState(o, rng);
    r.axis_mm = Park(o, 1e-3);
    ASSERT_TRUE(r.RunProgram(nc));
    r.Cycle(r.axis_mm);
    for (const auto& [id, a] : r.actions) EXPECT_FALSE(a.fired) << "ID " << id;
    ASSERT_FALSE(HasFailure()) << "trial " << trial;
  }
}

// Nothing of the first segment is applied before the axis reaches the thread start: at the call
// (every state between the part program's blocks) and along the approach from where the axis is
// parked, the control applies exactly what it applied before the call; at the thread start the
// plan takes over. Both directions of travel; far and near parking positions.
TEST(NcReplay, TheApproachKeepsWhatTheControlAppliedBeforeTheCall) {
  std::mt19937 rng(1805);
  int seen[2] = {0, 0};
  for (int trial = 0; trial < 24; ++trial) {
    const CutSetup s = RandomSetup(rng);
    const PlanOptions& o = s.options;
    ++seen[o.direction > 0];
    const CompensationPlan plan = BuildPlan(s.curve, s.feed_mm_s, s.thread_mm, o);
    const std::string nc = FormatNcProgram(plan);
    const double start = plan.segments.front().sd43920_mm;
    for (double before_mm : {0.01, 1.0, 50.0, 2000.0}) {
      replay::Replay r = FoundState(o, rng);
      r.actions.erase(o.sync_id_last);  // no stale action: the found values are what applies
      const double park = Park(o, before_mm);
      r.axis_mm = park;
      const replay::Control found = r.control;
      double worst_call_mm = 0;
      r.between_blocks = [&] {
        worst_call_mm = std::max(worst_call_mm, std::abs(r.control.DkMm(park) - found.DkMm(park)));
      };
      ASSERT_TRUE(r.RunProgram(nc));
      r.between_blocks = nullptr;
      EXPECT_EQ(worst_call_mm, 0.0) << "parked " << before_mm << " mm before the start";
      double worst_approach_mm = 0;
      for (int i = 0; i < 400; ++i) {  // up to, not onto, the thread start
        const double p = park + (start - park) * i / 400.0;
        r.Cycle(p);
        worst_approach_mm =
            std::max(worst_approach_mm, std::abs(r.control.DkMm(p) - found.DkMm(p)));
      }
      EXPECT_EQ(worst_approach_mm, 0.0) << "parked " << before_mm << " mm before the start";
      r.Cycle(start);
      EXPECT_NEAR(r.control.DkMm(start) * 1000.0 / SignFactor(o.sign), s.curve.ElongationUm(0.0),
                  o.tolerance_um)
          << "the plan applies from the thread start";
    }
    ASSERT_FALSE(HasFailure()) << "trial " << trial;
  }
  EXPECT_GT(seen[0], 3);
  EXPECT_GT(seen[1], 3);
}

// A profile's reserved range: with the machine builder's actions on every other ID 1..255, the
// plan and reset programs built from the shipped profile cancel and define only IDs inside the
// profile's sync_id_first..sync_id_last (plain and combined), and every other action survives a
// whole cut and the reset.
TEST(NcReplay, OnlyTheProfilesReservedRangeIsTouched) {
  const MachineProfile profile = LoadMachineProfile(std::string(WHIRL_SOURCE_DIR) +
                                                    "/datasets/machines/example_840d.json");
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({30.0, 250.0}, 4.0, 0.9);
  for (bool combined : {false, true}) {
    PlanOptions o;
    if (combined)
      profile.ApplyCombinedTo(o);
    else
      profile.ApplyTo(o);
    const CompensationPlan plan = BuildPlan(curve, 0.6, 1200.0, o);
    const std::string nc = FormatNcProgram(plan) + FormatNcResetProgram(o);
    const std::regex id_use(R"((?:CANCEL\(|ID=|IDS=)(\d+))");
    for (auto it = std::sregex_iterator(nc.begin(), nc.end(), id_use); it != std::sregex_iterator();
         ++it) {
      const int id = std::stoi((*it)[1]);
      EXPECT_TRUE(id >= profile.sync_id_first && id <= profile.sync_id_last) << (*it)[0];
    }
    replay::Replay r;
    r.axis_mm = Park(o, 10.0);
    r.control.ac_param[o.drift_alive_param] = combined ? 1 : 0;  // what a drift action writes
    for (int id = 1; id <= 255; ++id) {
      if (id >= profile.sync_id_first && id <= profile.sync_id_last) continue;
      replay::SyncAction builders;  // the machine builder's: every cycle, keeps the liveness
      builders.id = id;
      builders.is_static = true;
      builders.writes = {{"P" + std::to_string(o.drift_alive_param), combined ? "1" : "0"}};
      r.actions[id] = builders;
    }
    const std::size_t others = r.actions.size();
    ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan))) << "alarm " << r.control.alarm;
    for (int i = 0; i <= 2000; ++i)
      r.Cycle(AxisPositionMm(o, plan.axial_feed_mm_s, plan.cutting_time_s * i / 2000));
    r.EndProgram();
    ASSERT_TRUE(r.RunProgram(FormatNcResetProgram(o)));
    EXPECT_EQ(r.actions.size(), others) << "combined " << combined;
    for (const auto& [id, a] : r.actions)
      EXPECT_FALSE(id >= profile.sync_id_first && id <= profile.sync_id_last) << id;
  }
}

}  // namespace
}  // namespace whirl::interp
