// The NC programs replayed as a control would run them (tests/interp/nc_replay.h): the applied
// compensation follows the curve along the travel, and the control ends as it was found, after a
// complete cut, after an abort plus the reset program, and after a rerun without a reset.
#include <gtest/gtest.h>

#include <random>

#include "core/error.h"
#include "fit/arctan_curve.h"
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
    // Aborted halfway, then a rerun of the whole program without the reset program.
    r.RunProgram(nc);
    cut_to(0.5);
    r.EndProgram();
    EXPECT_NE(r.control.abs_value_mm, before.abs_value_mm);
    r.RunProgram(nc);
    cut_to(1.0);
    r.EndProgram();
    ExpectUnchanged(r.control, before);
    // Aborted again, then the reset program.
    r.RunProgram(nc);
    cut_to(0.3);
    r.EndProgram();
    r.RunProgram(FormatNcResetProgram(plan.options));
    ExpectUnchanged(r.control, before);
    // The reset program on a control where nothing is active changes nothing.
    r.RunProgram(FormatNcResetProgram(plan.options));
    ExpectUnchanged(r.control, before);
    // The axis stops a hair before the thread end (no run-out): the reset program called after
    // the cutting block, as documented, restores.
    r.RunProgram(nc);
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
      narrow.options.sync_id_first + static_cast<int>(plan.segments.size()) - 2;
  EXPECT_THROW(FormatNcProgram(narrow), InputError);
  narrow.options.sync_id_last += 1;  // exactly enough: later segments + the restore
  EXPECT_NO_THROW(FormatNcProgram(narrow));
}

}  // namespace
}  // namespace whirl::interp
