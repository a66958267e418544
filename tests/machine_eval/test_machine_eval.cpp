// The machine evaluation (machine_eval/machine_eval.h, field_eval.h): on a field machine that
// does not drift every workpiece row equals its counterpart of the workpiece-only strategy
// comparison, and the report screw an evaluation keeps is its first screw with its own curves.
#include <gtest/gtest.h>

#include <cmath>

#include "core/process.h"
#include "core/random.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"
#include "workpiece/model.h"

namespace whirl::machine_eval {
namespace {

struct EvalFixture {
  workpiece::WorkpieceModel model =
      workpiece::LoadWorkpieceModel(std::string(WHIRL_SOURCE_DIR) + "/models/default.json");
  compare::ExperienceRule rule = compare::BuildExperienceRule(
      ReadProcessTable(std::string(WHIRL_SOURCE_DIR) + "/datasets/whirling_500.csv", true));
  lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(
      std::string(WHIRL_SOURCE_DIR) + "/datasets/standards/iso3408_3_lead_tolerances.csv");
};

// One machine, one warm-up test, one laser test, two past production days, one test day.
FieldEvalOptions SmallEvaluation() {
  FieldEvalOptions o;
  o.machines = 1;
  o.threads = 1;
  o.calendar.warmup_speeds_m_min = {180};
  o.calendar.past_days = 2;
  o.calendar.test_days = 1;
  return o;
}

// A production scenario whose hall stays at 20 degC (no diurnal swing, noise, day offset, ramp or
// door), on a machine without heat sources: nothing moves the machine.
machine::MachineScenario StillHall() {
  machine::MachineScenario s = machine::FindMachineScenario("production");
  s.hall.amplitude_k = s.hall.ou_std_k = s.hall.day_offset_std_k = s.hall.ramp_std_k_per_h = 0;
  s.hall.door_events_per_day = 0;
  return s;
}

machine::FieldMachineConfig NoHeat() {
  machine::FieldMachineConfig c = machine::DefaultFieldMachine();
  c.head.bearing_power = c.head.motor_power = c.head.belt_power = 0;
  c.head.motor_cut_share = c.head.tool_heat_share = 0;
  c.z.motor_hold_power = c.z.motor_power_per_100mm_min = 0;
  c.z.bearing_torque_nm = c.z.nut_torque_nm = 0;
  c.bed.chip_share = c.bed.headstock_power = 0;
  return c;
}

void ExpectSameMetrics(const lead::LeadMetrics& a, const lead::LeadMetrics& b, const char* what) {
  EXPECT_NEAR(a.accumulated_1000_um, b.accumulated_1000_um, 1e-6) << what;
  EXPECT_NEAR(a.accumulated_total_um, b.accumulated_total_um, 1e-6) << what;
  EXPECT_NEAR(a.e_a_um, b.e_a_um, 1e-6) << what;
  EXPECT_NEAR(a.v_300_um, b.v_300_um, 1e-6) << what;
}

// Nothing moves the machine: the rows none, traditional, workpiece, class, table and nearest of
// every test-day cut equal the strategy comparison of the same screw, seed and hall (1e-6 um),
// and the machine's sources are zero. With the default machine the same cuts differ (the test can
// fail).
TEST(MachineEvaluation, WithoutMachineDriftTheWorkpieceRowsAreTheWorkpieceComparison) {
  const EvalFixture f;
  FieldEvalOptions o = SmallEvaluation();
  o.machine = NoHeat();
  const machine::MachineScenario still = StillHall();
  const MachineEvaluation e = EvaluateFieldScenario(still, f.model, f.rule, f.iso, o);
  const machine::MachineWorld w =
      machine::BuildMachineWorld(o.machine, still, o.seed, 0, o.calendar, o.timeline);
  const machine::DayPlan& day = w.timeline.Day(0);
  ASSERT_EQ(e.screws.size(), day.jobs.size());
  ASSERT_FALSE(e.screws.empty());
  using S = MachineStrategy;
  using C = compare::Strategy;
  const std::pair<S, C> rows[] = {{S::kNone, C::kNone},       {S::kTraditional, C::kTraditional},
                                  {S::kWorkpiece, C::kModel}, {S::kClass, C::kClass},
                                  {S::kTable, C::kTable},     {S::kNearest, C::kNearest}};
  for (std::size_t j = 0; j < day.jobs.size(); ++j) {
    const MachineEvalScrew& r = e.screws[j];
    ASSERT_TRUE(r.ok) << r.error;
    compare::CompareOptions co = o.compare;
    co.seed = MixSeed(day.seed, 0x77700 + j);
    co.disturbance.ambient_drift_fixed_k_per_h = 0;  // the still hall's slope over the cut
    const compare::ScrewComparison c =
        compare::CompareScrew(day.jobs[j].screw, f.model, f.rule, f.iso, co);
    for (const auto& [mine, theirs] : rows)
      ExpectSameMetrics(r.metrics[static_cast<std::size_t>(mine)], c.Outcome(theirs).metrics,
                        ToString(mine).c_str());
    EXPECT_NEAR(r.source_total_um[static_cast<std::size_t>(ErrorSource::kHead)], 0.0, 1e-6);
    EXPECT_NEAR(r.source_total_um[static_cast<std::size_t>(ErrorSource::kZAxis)], 0.0, 1e-6);
  }
  // The default machine in the same hall drifts: the same first cut leaves more uncompensated.
  FieldEvalOptions heat = SmallEvaluation();
  const MachineEvaluation h = EvaluateFieldScenario(still, f.model, f.rule, f.iso, heat);
  ASSERT_FALSE(h.screws.empty());
  ASSERT_TRUE(h.screws[0].ok);
  EXPECT_GT(std::abs(h.screws[0].metrics[0].accumulated_total_um -
                     e.screws[0].metrics[0].accumulated_total_um),
            1.0);
}

// The report screw is the first test-day screw of machine 0 as the evaluation scored it: its
// curves give its metrics, its log runs from the day's power-on past the end of its cut, its
// drift models are the sensor model's channels with the training ranges; only on request, and
// over seeds only in the first.
TEST(MachineEvaluation, TheReportScrewIsTheFirstScrewWithItsOwnCurves) {
  const EvalFixture f;
  FieldEvalOptions o = SmallEvaluation();
  o.keep_report_screw = true;
  const SeedsEvaluation s = EvaluateFieldOverSeeds(machine::FindMachineScenario("production"),
                                                   f.model, f.rule, f.iso, o, 2);
  ASSERT_EQ(s.runs.size(), 2u);
  EXPECT_FALSE(s.runs[1].report);  // asked for in the first seed only
  const MachineEvaluation& e = s.runs[0];
  ASSERT_TRUE(e.report);
  const ReportScrew& r = *e.report;
  ASSERT_TRUE(e.screws.front().ok);
  EXPECT_EQ(r.result.machine, 0);
  EXPECT_EQ(r.result.screw.name, e.screws.front().screw.name);
  EXPECT_EQ(r.scenario, "production");
  lead::LeadMetricOptions mo = o.compare.metrics;
  mo.lead_mm = r.result.screw.process.pitch_mm;
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    const lead::LeadMetrics m = lead::ComputeLeadMetrics(r.leads[k], mo);
    EXPECT_EQ(m.accumulated_total_um, e.screws.front().metrics[k].accumulated_total_um)
        << ToString(static_cast<MachineStrategy>(k));
  }
  ASSERT_GT(r.log.samples(), 2);
  EXPECT_EQ(r.log.other(0, r.log.OtherIndex("power_on")), 0.0);  // the power-on sample
  EXPECT_GE(r.log.time_min.back(), r.cut_end_min);
  EXPECT_LT(r.cut_start_min, r.cut_end_min);
  EXPECT_GT(r.cut_start_min, r.log.time_min.front());
  EXPECT_NEAR(r.cut_end_min - r.cut_start_min, r.kinematics.cutting_time_s / 60.0, 1e-9);
  EXPECT_EQ(r.sensors, e.sensors.front());
  EXPECT_EQ(r.sensors_choice, e.sensors_choice.front());
  EXPECT_EQ(r.offset.features.size(), r.slope.features.size());
  ASSERT_GT(r.offset.features.size(), 0u);
  EXPECT_LT(r.offset.feature_max.maxCoeff(), 1e6);  // the training range, not unbounded
  EXPECT_EQ(r.z_ref_mm, o.machine.z.fixed_end_mm);
}

}  // namespace
}  // namespace whirl::machine_eval
