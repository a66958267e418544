// The NC programs replayed as a control would run them (tests/interp/nc_replay.h): the applied
// compensation follows the curve along the travel, and the control ends as it was found, after a
// complete cut, after an abort plus the reset program, and after a rerun without a reset.
#include <gtest/gtest.h>

#include <iterator>
#include <random>
#include <regex>

#include "core/error.h"
#include "fit/arctan_curve.h"
#include "interp/drift_action.h"
#include "interp/machine_profile.h"
#include "interp/nc_replay.h"
#include "interp/profile_uses.h"
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

// Setting data, R parameters, $AC_PARAM and every synchronized action (ID, kind, condition,
// writes) exactly as before.
void ExpectControlAsFound(const replay::Replay& now, const replay::Replay& before) {
  ExpectUnchanged(now.control, before.control);
  EXPECT_EQ(now.control.r, before.control.r) << "R parameters";
  EXPECT_EQ(now.control.ac_param, before.control.ac_param) << "$AC_PARAM";
  ASSERT_EQ(now.actions.size(), before.actions.size()) << "an action added or cancelled";
  for (const auto& [id, a] : before.actions) {
    const auto it = now.actions.find(id);
    ASSERT_NE(it, now.actions.end()) << "ID " << id << " cancelled";
    const replay::SyncAction& b = it->second;
    EXPECT_TRUE(b.is_static == a.is_static && b.mode == a.mode && b.lhs == a.lhs &&
                b.op == a.op && b.rhs == a.rhs && b.writes.size() == a.writes.size())
        << "ID " << id << " redefined";
    for (std::size_t k = 0; k < a.writes.size() && k < b.writes.size(); ++k)
      EXPECT_TRUE(b.writes[k].target == a.writes[k].target && b.writes[k].expr == a.writes[k].expr)
          << "ID " << id << " redefined";
  }
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
      // The replay goes on after SETAL: the program's own jump keeps the control as found.
      EXPECT_FALSE(r.RunProgram(nc)) << "started at " << past[k];
      EXPECT_EQ(r.control.alarms, std::vector<int>{o.start_alarm});
      ExpectControlAsFound(r, before);
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
      const double worst_approach_mm = r.WorstDeviationOnApproach(park, start, 400, found);
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

// Every start check that fails (axis at or past the thread start, the drift action missing,
// running beside a plan that writes the setting data itself or in the other mode, a plan's own
// compensation still active when the drift program starts) raises exactly its alarm and leaves
// the control exactly as found: setting data, R parameters, $AC_PARAM and every action. The
// replay does not stop at SETAL (a display-only alarm does not), so this is the programs' own
// jump to their end at work. Both shipped profiles (offset only, and slope handed over).
TEST(NcReplay, EveryFailedStartCheckJumpsToTheEndAndChangesNothing) {
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({30.0, 250.0}, 4.0, 0.9);
  for (const char* file : {"example_840d.json", "whirling_840d.json"}) {
    SCOPED_TRACE(file);
    const MachineProfile profile =
        LoadMachineProfile(std::string(WHIRL_SOURCE_DIR) + "/datasets/machines/" + file);
    const DriftActionOptions d = profile.DriftOptions();
    const std::string sensor = d.inputs.begin()->first;
    const drift::DriftModel m = testing::OneSensorModel(sensor, "offset_um");
    const drift::DriftModel g = testing::OneSensorModel(sensor, "zscrew_per_1000_um");
    PlanOptions plain, combined;
    profile.ApplyTo(plain);
    profile.ApplyCombinedTo(combined);
    const CompensationPlan plain_plan = BuildPlan(curve, 0.6, 1200.0, plain);
    const CompensationPlan combined_plan = BuildPlan(curve, 0.6, 1200.0, combined);
    // The drift program in the mode the combined plan expects (2 with the slope handed over,
    // else 1), and in the other one.
    const bool handover = combined.workpiece_slope_param >= 0;
    DriftActionOptions other = d;
    other.workpiece_slope_param = handover ? -1 : d.workpiece_k0_param - 2;  // the 2 slots below
    if (handover) other.blank_param = -1;  // the blank latch belongs to the handed-over slope
    const std::string drift_expected = handover ? FormatDriftNcProgram(m, d, "", &g)
                                                : FormatDriftNcProgram(m, d);
    const std::string drift_other_mode = FormatDriftNcProgram(m, other);
    const double before_start = Park(plain, 10.0), past_start = Park(plain, -100.0);
    const int a = d.missing_alarm;
    struct Case {
      std::string what;
      std::string running;  // the drift program already running ("" none)
      double axis_mm;
      bool plan_active;  // a plan's own compensation left active (its marker R = 1)
      std::string program;
      int alarm;
    };
    std::vector<Case> cases = {
        {"plain plan, axis past the start", "", past_start, false, FormatNcProgram(plain_plan),
         plain.start_alarm},
        {"combined plan, axis past the start", drift_expected, past_start, false,
         FormatNcProgram(combined_plan), combined.start_alarm},
        {"plain plan beside a running drift action", drift_expected, before_start, false,
         FormatNcProgram(plain_plan), a + 1},
        {"combined plan without the drift action", "", before_start, false,
         FormatNcProgram(combined_plan), a},
        {"drift program, a plan's compensation active", "", before_start, true,
         FormatDriftNcProgram(m, d), a + 3},
        {"combined plan, drift action in the other mode", drift_other_mode, before_start, false,
         FormatNcProgram(combined_plan), a + 2}};
    for (const Case& c : cases) {
      SCOPED_TRACE(c.what);
      replay::Replay r;
      r.axis = profile.axis;
      r.axis_mm = c.axis_mm;
      r.control.abs_value_mm = 0.0031;  // found values
      r.control.slope = -2e-6;
      r.control.ref_position_mm = 250.0;
      for (int k = 0; k < 4; ++k) r.control.r[profile.save_r_first + k] = 11.0 + k;
      for (int k = 0; k < 5; ++k) r.control.r[d.save_r_first + k] = 21.0 + k;
      r.control.r[profile.save_r_first + 3] = c.plan_active ? 1 : 0;
      r.control.r[d.save_r_first + 1] = r.control.r[d.save_r_first + 4] = 0;
      r.control.ain[d.inputs.at(sensor).index] = 230.0;
      r.control.ac_param[d.param_first] = 0;  // the liveness slot: no action has written it
      if (!c.running.empty()) {
        ASSERT_TRUE(r.RunProgram(c.running)) << "alarm " << r.control.alarm;
        r.EndProgram();
      }
      for (int id : {profile.sync_id_last, d.sync_id_last}) {  // leftovers in whirl's ranges
        replay::SyncAction stale;
        stale.id = id;
        stale.is_static = true;
        stale.writes = {{"P" + std::to_string(d.param_last), "7"}};
        r.actions[id] = stale;
      }
      for (int k = 0; k < 3; ++k) r.Cycle(c.axis_mm);  // a running action at its steady state
      const replay::Replay before = r;
      r.control.alarms.clear();
      EXPECT_FALSE(r.RunProgram(c.program));
      EXPECT_EQ(r.control.alarms, std::vector<int>{c.alarm}) << "exactly its own alarm";
      r.Cycle(c.axis_mm);
      replay::Replay expected = before;
      expected.Cycle(c.axis_mm);  // what the running actions write in that cycle anyway
      ExpectControlAsFound(r, expected);
    }
  }
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

// Issue 45 item 5: a plan program run again after a cut that never reached its restore (aborted
// at 40 % and the axis moved back, or a power failure at 50 %), without the reset program, and a
// plan program called twice in a row: the values it saves are those found before the first run,
// the approach applies exactly them (no step by the old plateau at the thread start), and the
// whole cut ends with the control as found.
TEST(NcReplay, ARerunAfterAnAbortOrAPowerFailureStartsFromTheFoundValues) {
  std::mt19937 rng(1806);
  const char* what[] = {"aborted at 40 %", "power failure at 50 %", "called twice in a row"};
  for (int trial = 0; trial < 12; ++trial) {
    const CutSetup s = RandomSetup(rng);
    const PlanOptions& o = s.options;
    const CompensationPlan plan = BuildPlan(s.curve, s.feed_mm_s, s.thread_mm, o);
    const std::string nc = FormatNcProgram(plan);
    const double t_end = s.thread_mm / s.feed_mm_s;
    const double start = plan.segments.front().sd43920_mm;
    const double park = Park(o, 20.0);
    const int m = o.save_r_first;
    for (int how = 0; how < 3; ++how) {
      SCOPED_TRACE(std::string(what[how]) + ", trial " + std::to_string(trial));
      replay::Replay r = FoundState(o, rng);
      r.actions.erase(o.sync_id_last);  // no stale action: the found values are what applies
      const replay::Control found = r.control;
      ASSERT_TRUE(r.RunProgram(nc));
      if (how < 2) {
        const double stop_s = (how == 0 ? 0.4 : 0.5) * t_end;
        for (int i = 0; i <= 1000; ++i) r.Cycle(AxisPositionMm(o, s.feed_mm_s, stop_s * i / 1000));
        if (how == 0)
          r.EndProgram();
        else
          r.PowerOn();
        ASSERT_NE(r.control.abs_value_mm, found.abs_value_mm) << "stopped on the plan's values";
        ASSERT_EQ(r.control.r[m + 3], 1.0) << "the marker says: not restored";
      }
      r.Cycle(park);  // the axis moved back before the thread start
      ASSERT_TRUE(r.RunProgram(nc)) << "alarm " << r.control.alarm;
      EXPECT_EQ(r.control.r[m], found.abs_value_mm) << "saved SD43900 is the found one";
      EXPECT_EQ(r.control.r[m + 1], found.slope);
      EXPECT_EQ(r.control.r[m + 2], found.ref_position_mm);
      EXPECT_EQ(r.WorstDeviationOnApproach(park, start, 400, found), 0.0) << "the approach";
      const double sgn = SignFactor(o.sign);
      r.Cycle(start);
      EXPECT_NEAR(r.control.DkMm(start) * 1000.0 / sgn, s.curve.ElongationUm(0.0), o.tolerance_um)
          << "at the thread start the plan takes over from the found values";
      for (int i = 0; i <= 2000; ++i) r.Cycle(AxisPositionMm(o, s.feed_mm_s, t_end * i / 2000));
      r.Cycle(AxisPositionMm(o, s.feed_mm_s, t_end) + o.direction);  // run-out
      r.EndProgram();
      ExpectUnchanged(r.control, found);
      EXPECT_EQ(r.control.r[m + 3], 0.0) << "marker cleared";
    }
    ASSERT_FALSE(HasFailure());
  }
}

// A machine with the live drift action (both shipped profiles: the plan hands K0 over, or K0 and
// slope): the drift program running, then the combined plan aborted, cut after a power failure,
// or called twice. `reference` runs the same drift program and cycles without any plan: what the
// control must apply whenever no plan is in its cut.
struct DriftMachine {
  MachineProfile profile;
  DriftActionOptions d;
  PlanOptions o;
  CompensationPlan plan;
  std::string drift_nc, drift_reset, plan_nc, plan_reset;
};

DriftMachine ShippedDriftMachine(const std::string& file) {
  DriftMachine dm;
  dm.profile = LoadMachineProfile(std::string(WHIRL_SOURCE_DIR) + "/datasets/machines/" + file);
  dm.d = dm.profile.DriftOptions();
  const std::string sensor = dm.d.inputs.begin()->first;
  const drift::DriftModel m = testing::OneSensorModel(sensor, "offset_um");
  const drift::DriftModel g = testing::OneSensorModel(sensor, "zscrew_per_1000_um");
  dm.profile.ApplyCombinedTo(dm.o);
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({30.0, 250.0}, 4.0, 0.9);
  dm.plan = BuildPlan(curve, 0.6, 1200.0, dm.o);
  dm.drift_nc = dm.o.workpiece_slope_param >= 0 ? FormatDriftNcProgram(m, dm.d, "", &g)
                                                : FormatDriftNcProgram(m, dm.d);
  dm.drift_reset = FormatDriftNcResetProgram(dm.d);
  dm.plan_nc = FormatNcProgram(dm.plan);
  dm.plan_reset = FormatNcResetProgram(dm.o);
  return dm;
}

replay::Replay FoundDriftMachine(const DriftMachine& dm) {
  replay::Replay r;
  r.axis = dm.profile.axis;
  r.axis_mm = Park(dm.o, 30.0);
  r.control.abs_value_mm = 0.0031;  // found values
  r.control.slope = -2e-6;
  r.control.ref_position_mm = 250.0;
  for (int k = 0; k < 4; ++k) r.control.r[dm.profile.save_r_first + k] = 11.0 + k;
  for (int k = 0; k < 5; ++k) r.control.r[dm.d.save_r_first + k] = 21.0 + k;
  r.control.r[dm.profile.save_r_first + 3] = 0;
  r.control.r[dm.d.save_r_first + 1] = r.control.r[dm.d.save_r_first + 4] = 0;
  r.control.ain[dm.d.inputs.begin()->second.index] = 230.0;
  return r;
}

// Moves both replays through the same positions; returns the largest |dK - reference's dK|, mm.
double Travel(replay::Replay& r, replay::Replay& reference, const std::vector<double>& positions) {
  double worst_mm = 0;
  for (double p : positions) {
    r.Cycle(p);
    reference.Cycle(p);
    worst_mm = std::max(worst_mm, std::abs(r.control.DkMm(p) - reference.control.DkMm(p)));
  }
  return worst_mm;
}

std::vector<double> Positions(double from_mm, double to_mm, int n) {
  std::vector<double> p;
  for (int i = 0; i <= n; ++i) p.push_back(from_mm + (to_mm - from_mm) * i / n);
  return p;
}

TEST(NcReplay, CombinedPlanAfterAnAbortAPowerFailureOrTwiceStartsFromTheDriftActionAlone) {
  for (const char* file : {"example_840d.json", "whirling_840d.json"}) {
    const DriftMachine dm = ShippedDriftMachine(file);
    const PlanOptions& o = dm.o;
    const bool handover = o.workpiece_slope_param >= 0;
    const double feed = dm.plan.axial_feed_mm_s, t_end = dm.plan.cutting_time_s;
    const double park = Park(o, 30.0), start = dm.plan.segments.front().sd43920_mm;
    const double end = AxisPositionMm(o, feed, t_end) + o.direction;
    const auto cut = [&](double fraction) {
      return Positions(start, AxisPositionMm(o, feed, fraction * t_end), 600);
    };
    for (int how = 0; how < 3; ++how) {
      SCOPED_TRACE(std::string(file) + (how == 0   ? ": aborted at 40 %"
                                        : how == 1 ? ": power failure at 50 %"
                                                   : ": called twice in a row"));
      replay::Replay r = FoundDriftMachine(dm);
      const replay::Control found = r.control;
      ASSERT_TRUE(r.RunProgram(dm.drift_nc)) << "alarm " << r.control.alarm;
      r.EndProgram();
      replay::Replay reference = r;  // the drift action alone from here on
      Travel(r, reference, {park, park, park});
      ASSERT_TRUE(r.RunProgram(dm.plan_nc)) << "alarm " << r.control.alarm;
      if (how == 0) {
        Travel(r, reference, cut(0.4));
        r.EndProgram();  // the drift action's static actions stay
      } else if (how == 1) {
        Travel(r, reference, cut(0.5));
        r.PowerOn();  // every action and $AC_PARAM gone; setting data and R stay
        reference.PowerOn();
        r.Cycle(park);
        r.control.alarms.clear();
        EXPECT_FALSE(r.RunProgram(dm.plan_nc)) << "the drift action is not running";
        EXPECT_EQ(r.control.alarms, std::vector<int>{dm.d.missing_alarm});
        r.control.alarms.clear();
        if (!handover) {  // the plan's marker is set: the drift program wants the reset first
          EXPECT_FALSE(r.RunProgram(dm.drift_nc));
          EXPECT_EQ(r.control.alarms, std::vector<int>{dm.d.missing_alarm + 3});
          ASSERT_TRUE(r.RunProgram(dm.plan_reset));
        }
        ASSERT_TRUE(r.RunProgram(dm.drift_nc)) << "alarm " << r.control.alarm;
        r.EndProgram();
        ASSERT_TRUE(reference.RunProgram(dm.drift_nc));
        reference.EndProgram();
      }
      Travel(r, reference, Positions(r.axis_mm, park, 50));  // back before the thread start
      ASSERT_TRUE(r.RunProgram(dm.plan_nc)) << "alarm " << r.control.alarm;
      const double before_start = start - o.direction * 1e-3;  // at the start the plan takes over
      EXPECT_LE(Travel(r, reference, Positions(park, before_start, 400)), 1e-12)
          << "the approach applies the drift action alone";
      Travel(r, reference, cut(1.0));
      Travel(r, reference, {end});
      EXPECT_LE(std::abs(r.control.DkMm(end) - reference.control.DkMm(end)), 1e-12)
          << "after the cut the drift action alone again";
      r.EndProgram();
      ASSERT_TRUE(r.RunProgram(dm.plan_reset));
      ASSERT_TRUE(r.RunProgram(dm.drift_reset));
      ExpectUnchanged(r.control, found);
      EXPECT_EQ(r.control.r[dm.profile.save_r_first + 3], 0.0);
      EXPECT_EQ(r.control.r[dm.d.save_r_first + 1], 0.0);
      EXPECT_EQ(r.control.r[dm.d.save_r_first + 4], 0.0);
    }
  }
}

// The drift program run twice in a row, or again after a power failure, saves only what it
// found before its first run: its reset program gives back the machine's own values, also when
// called after a power failure without a rerun, and a second reset changes nothing.
TEST(NcReplay, DriftProgramTwiceOrAfterAPowerFailureResetsToTheFoundValues) {
  for (const char* file : {"example_840d.json", "whirling_840d.json"}) {
    const DriftMachine dm = ShippedDriftMachine(file);
    for (int how = 0; how < 3; ++how) {
      SCOPED_TRACE(std::string(file) + ", case " + std::to_string(how));
      replay::Replay r = FoundDriftMachine(dm);
      const replay::Control found = r.control;
      ASSERT_TRUE(r.RunProgram(dm.drift_nc));
      for (int k = 0; k < 3; ++k) r.Cycle(r.axis_mm);
      ASSERT_NE(r.control.abs_value_mm, found.abs_value_mm) << "the action writes SD43900";
      if (how == 0) {
        ASSERT_TRUE(r.RunProgram(dm.drift_nc));  // twice in a row
      }
      if (how >= 1) r.PowerOn();
      if (how == 1) {
        ASSERT_TRUE(r.RunProgram(dm.drift_nc));  // restarted after the power failure
      }
      for (int k = 0; k < 3; ++k) r.Cycle(r.axis_mm);
      ASSERT_TRUE(r.RunProgram(dm.drift_reset));
      ExpectUnchanged(r.control, found);
      ASSERT_TRUE(r.RunProgram(dm.drift_reset));
      ExpectUnchanged(r.control, found);
    }
  }
}

}  // namespace
}  // namespace whirl::interp
