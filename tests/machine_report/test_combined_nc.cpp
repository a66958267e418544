// The combined 840D programs of a screw on the field machine (machine_report/machine_nc.h),
// replayed as the control runs them (tests/interp/nc_replay.h) from the day's power-on, with the
// control's log (its filtered temperatures and duty signals) on the analog inputs: at every
// control sample the control applies the workpiece plan plus what the evaluation's both_shop
// applies from that sample on (the sensor model a shop trained, drift/joint.h, run causally:
// machine_eval/strategies.h, K0_k + G_k (z_ref - z) / 1000); while the axis waits before the
// thread start, the machine line alone; the reset programs leave the control as found. The
// analog inputs hold each sample's values over the interval that ends at it (the interval the
// causal evaluator's lag step covers), so the two agree at the samples; between samples the
// control moves on every cycle while both_shop holds the last sample.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/process.h"
#include "drift/grey_box.h"
#include "drift/grey_box_io.h"
#include "drift/joint.h"
#include "interp/nc_replay.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"
#include "machine_eval/strategies.h"
#include "machine_report/machine_nc.h"
#include "support/scratch_dir.h"
#include "workpiece/model.h"

namespace whirl::machine_report {
namespace {

constexpr double kReplayCycleMs = 100;  // the largest cycle the profile allows: 100 per sample

std::string CombinedSource(const std::string& rel) {
  return std::string(WHIRL_SOURCE_DIR) + "/" + rel;
}

// The first test-day screw of a constant-duty machine (one cut right after power-on) whose
// screws have 400 mm of thread (about ten minutes of cut), with the models trained on its
// history (one warm-up test, one laser test, two past days).
const machine_eval::ReportScrew& ShortCut() {
  static const machine_eval::ReportScrew* kept = [] {
    machine::MachineScenario s = machine::FindMachineScenario("constant-duty");
    s.jobs.base.thread_length_mm = 400;
    machine_eval::FieldEvalOptions o;
    o.machines = 1;
    o.threads = 1;
    o.seed = 2;
    o.calendar.warmup_speeds_m_min = {180};
    o.calendar.past_days = 2;
    o.calendar.test_days = 1;
    o.keep_report_screw = true;
    o.protocol.grey_candidates = true;  // the mix's rule and weight (grey_short_mix)
    const machine_eval::MachineEvaluation e = machine_eval::EvaluateFieldScenario(
        s, workpiece::LoadWorkpieceModel(CombinedSource("models/default.json")),
        compare::BuildExperienceRule(
            ReadProcessTable(CombinedSource("datasets/whirling_500.csv"), true)),
        lead::ReadIsoToleranceTable(
            CombinedSource("datasets/standards/iso3408_3_lead_tolerances.csv")),
        o);
    if (!e.report) throw std::runtime_error("no report screw");
    return new machine_eval::ReportScrew(*e.report);
  }();
  return *kept;
}

// The shipped profile with the replay's cycle (direction -1), or the same machine seen from an
// axis that runs +Z towards the chuck (direction +1: program coordinate -z, the fixed bearing at
// offset - z_fixed).
interp::MachineProfile CombinedProfile(int direction, interp::ControlDk control_dk,
                                       double z_fixed_mm) {
  interp::MachineProfile p =
      interp::LoadMachineProfile(CombinedSource("datasets/machines/whirling_840d.json"));
  p.control_dk = control_dk;
  p.drift->ipo_cycle_ms = kReplayCycleMs;
  if (direction == 1) {
    p.direction = 1;
    p.drift->error_direction = 1;
    p.drift->slope_growth_direction = 1;
    p.drift->slope_fixed_end_mm = p.machine_offset_mm - z_fixed_mm;
  }
  return p;
}

CombinedPrograms Build(const machine_eval::ReportScrew& r, const interp::MachineProfile& p) {
  return BuildCombinedPrograms(r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm,
                               r.plan_options, r.offset, r.slope, r.z_ref_mm, p, "test curve",
                               "test model");
}

// One replayed day of a screw's combined programs: the control's analog inputs fed from the
// log's raw inputs, the axis parked 5 mm before the thread start until the cut, then following
// the plan's feed; power-on starts the drift action on the first sample, then the plan.
struct DayReplay {
  DayReplay(const machine_eval::ReportScrew& screw, const CombinedPrograms& programs,
            Eigen::MatrixXd raw_inputs, std::vector<std::string> input_names)
      : r(screw), p(programs), raw(std::move(raw_inputs)), inputs(std::move(input_names)),
        feed(screw.kinematics.axial_feed_mm_s), t_cut(screw.kinematics.cutting_time_s),
        z0(screw.kinematics.thread_start_position_mm),
        park(interp::AxisPositionMm(programs.plan.options, feed, -5.0 / feed)) {
    replay.control.abs_value_mm = -0.0013;  // what the control holds before
    replay.control.slope = 7e-6;
    replay.control.ref_position_mm = 100.0;
  }
  void SetInputs(int k) {
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      const interp::AnalogInput& a = p.drift.inputs.at(inputs[i]);
      replay.control.ain[a.index] = (raw(k, static_cast<Eigen::Index>(i)) - a.offset) / a.scale;
    }
  }
  double CutTimeS(double t_min) const { return (t_min - r.cut_start_min) * 60.0; }
  double AxisAt(double t_min) const {  // where the axis is at log time t_min
    const double t_s = CutTimeS(t_min);
    return t_s < 0 ? park : interp::AxisPositionMm(p.plan.options, feed, std::min(t_s, t_cut));
  }
  double ZAt(double t_min) const {  // the tool's distance from the chuck face
    const double t_s = CutTimeS(t_min);
    return t_s < 0 ? z0 + 5.0 : z0 - feed * std::min(t_s, t_cut);
  }
  void PowerOn() {
    SetInputs(0);
    replay.axis_mm = park;
    ASSERT_TRUE(replay.RunProgram(p.drift_nc));
    replay.Cycle(park);
    ASSERT_TRUE(replay.RunProgram(p.plan_nc));
  }
  // Sample k-1 -> k: the inputs of sample k, one control cycle at a time.
  void Advance(int k, int per_sample) {
    const double t0 = r.log.time_min[static_cast<std::size_t>(k - 1)];
    const double t1 = r.log.time_min[static_cast<std::size_t>(k)];
    SetInputs(k);
    for (int c = 1; c <= per_sample; ++c) replay.Cycle(AxisAt(t0 + (t1 - t0) * c / per_sample));
  }
  // One step of a replay loop: Advance to sample k, then where the day is at that sample.
  struct Sample {
    std::size_t k;
    double t_min, pos_mm;
    bool cutting;
  };
  Sample Step(int k, int per_sample) {
    Advance(k, per_sample);
    const double t = r.log.time_min[static_cast<std::size_t>(k)];
    return {static_cast<std::size_t>(k), t, AxisAt(t), CutTimeS(t) >= 0 && CutTimeS(t) < t_cut};
  }
  // After the cut: both reset programs; the control holds what it held before.
  void EndAndReset() {
    replay.Cycle(interp::AxisPositionMm(p.plan.options, feed, t_cut) - 1.0);
    replay.EndProgram();
    ASSERT_TRUE(replay.RunProgram(p.plan_reset_nc));
    ASSERT_TRUE(replay.RunProgram(p.drift_reset_nc));
    EXPECT_TRUE(replay.actions.empty());
    EXPECT_EQ(replay.control.abs_value_mm, -0.0013);
    EXPECT_EQ(replay.control.slope, 7e-6);
    EXPECT_EQ(replay.control.ref_position_mm, 100.0);
  }

  const machine_eval::ReportScrew& r;
  const CombinedPrograms& p;
  Eigen::MatrixXd raw;
  std::vector<std::string> inputs;
  double feed, t_cut, z0, park;
  interp::replay::Replay replay;
};

int SamplesPerInterval(const drift::Run& log) {
  return static_cast<int>(
      std::lround((log.time_min[1] - log.time_min[0]) * 60000.0 / kReplayCycleMs));
}

void ReplayTheDay(int direction, interp::ControlDk control_dk) {
  SCOPED_TRACE("direction " + std::to_string(direction) + ", control_dk " +
               interp::ToString(control_dk));
  const machine_eval::ReportScrew& r = ShortCut();
  const drift::Run& log = r.log;
  const CombinedPrograms p = Build(r, CombinedProfile(direction, control_dk, r.z_ref_mm));
  const machine_eval::HeldSamples held = machine_eval::RunCausally(r.sensor_model, log);
  std::vector<std::string> inputs = r.sensor_model.sensors;
  inputs.insert(inputs.end(), r.sensor_model.other_inputs.begin(),
                r.sensor_model.other_inputs.end());
  DayReplay day(r, p, drift::JointRawInputs(r.sensor_model, log), inputs);
  const double s = interp::SignFactor(p.plan.options.sign);
  day.PowerOn();
  if (::testing::Test::HasFatalFailure()) return;
  const int per_sample = SamplesPerInterval(log);
  double worst_um = 0, worst_parked_um = 0, largest_machine_um = 0;
  int cut_samples = 0;
  for (int k = 1; k < log.samples(); ++k) {
    const double t0 = log.time_min[static_cast<std::size_t>(k - 1)];
    const double t1 = log.time_min[static_cast<std::size_t>(k)];
    ASSERT_EQ(static_cast<int>(std::lround((t1 - t0) * 60000.0 / kReplayCycleMs)), per_sample);
    day.Advance(k, per_sample);
    if (::testing::Test::HasFailure()) return;
    const double pos = day.AxisAt(t1);
    const double machine_um =
        held.k0_um[static_cast<std::size_t>(k)] +
        held.slope_um_per_1000[static_cast<std::size_t>(k)] * (r.z_ref_mm - day.ZAt(t1)) / 1000.0;
    const double applied_um = day.replay.control.DkMm(pos) * 1000.0 / s;
    largest_machine_um = std::max(largest_machine_um, std::abs(machine_um));
    if (t1 < r.cut_start_min) {  // parked before the thread start: the machine line alone
      worst_parked_um = std::max(worst_parked_um, std::abs(applied_um - machine_um));
    } else if (t1 <= r.cut_end_min) {
      ++cut_samples;
      worst_um = std::max(
          worst_um, std::abs(applied_um - machine_um - interp::AppliedCompensationUm(p.plan, pos)));
    }
  }
  EXPECT_GT(cut_samples, 30);
  EXPECT_LT(worst_um, 1e-3);
  EXPECT_LT(worst_parked_um, 1e-3);
  EXPECT_GT(largest_machine_um, 2.0);  // the machine part is not trivially zero
  // The plan never writes a setting datum itself; after the cut and both resets the control
  // holds what it held before.
  EXPECT_EQ(p.plan_nc.find("SA_TEMP_COMP"), std::string::npos);
  day.EndAndReset();
}

TEST(CombinedPrograms, ReplayAppliesPlanPlusTheShopTrainedModelAtEveryControlSample) {
  ASSERT_GT(ShortCut().sensor_model.features(), 0);
  for (int direction : {-1, 1})
    for (auto control_dk : {interp::ControlDk::kAdded, interp::ControlDk::kSubtracted})
      ReplayTheDay(direction, control_dk);
}

// The grey box's combined programs over the same day: at every control sample the control
// applies the plan plus what both_grey applies (machine_eval/strategies.h RunCausally on the grey
// box: K0_k + (G_k + g_b (B_latched - 20)) (z_ref - z) / 1000), B latched by the plan at the
// thread start and held for the cut; parked before it and after the cut, no blank term. The
// control latches B of the cycle the axis reaches the thread start, the evaluation the last
// control sample before it: the two agree within what B moves in one sample interval.
TEST(CombinedPrograms, ReplayAppliesPlanPlusTheGreyBoxWithTheLatchedBlank) {
  const machine_eval::ReportScrew& r = ShortCut();
  ASSERT_FALSE(r.grey.blank_sensor.empty());
  const CombinedPrograms p = BuildCombinedGreyPrograms(
      r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm, r.plan_options, r.grey,
      CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm), "test curve", "test grey box");
  ASSERT_TRUE(p.grey);
  const drift::Run& log = r.log;
  const machine_eval::HeldSamples held = machine_eval::RunCausally(r.grey, log);
  const int blank = p.drift.blank_param;
  DayReplay day(r, p, drift::GreyBoxRawInputs(r.grey, log), r.grey.Inputs());
  interp::replay::Replay& replay = day.replay;
  const double s = interp::SignFactor(p.plan.options.sign);
  day.PowerOn();
  if (::testing::Test::HasFatalFailure()) return;
  const int per_sample = SamplesPerInterval(log);
  const std::size_t at_start = held.IndexAt(r.cut_start_min);
  const double g_b = r.grey.blank_um_per_1000_per_k;
  double worst_um = 0, latched = NAN, b_moved = 0;
  int cut_samples = 0;
  for (int k = 1; k < log.samples(); ++k) {
    const auto [uk, t1, pos, cutting] = day.Step(k, per_sample);
    if (::testing::Test::HasFailure()) return;
    const double latch = replay.control.ac_param[blank + 1];
    if (cutting) {
      if (std::isnan(latched)) latched = latch;
      EXPECT_EQ(latch, latched) << "the latch moved during the cut, sample " << k;
      b_moved = std::max(b_moved, std::abs(replay.control.ac_param[blank] - latched));
    } else {
      EXPECT_EQ(latch, interp::kBlankNeutralC) << "sample " << k;
    }
    const double g = held.slope_um_per_1000[uk] + (cutting ? g_b * (latch - 20.0) : 0.0);
    const double machine_um = held.k0_um[uk] + g * (r.z_ref_mm - day.ZAt(t1)) / 1000.0;
    const double applied_um = replay.control.DkMm(pos) * 1000.0 / s;
    const double plan_um = cutting ? interp::AppliedCompensationUm(p.plan, pos) : 0.0;
    worst_um = std::max(worst_um, std::abs(applied_um - machine_um - plan_um));
    cut_samples += cutting;
  }
  EXPECT_GT(cut_samples, 30);
  EXPECT_LT(worst_um, 1e-3);
  // The latched value is the evaluation's B at the cut start within what B moves in one sample.
  const double b_eval = 20.0 + held.blank_slope_um_per_1000[at_start] / g_b;
  EXPECT_LT(std::abs(latched - b_eval), 0.05) << latched << " vs " << b_eval;
  EXPECT_GT(b_moved, 0.0);
  day.EndAndReset();
  EXPECT_EQ(replay.control.ac_param[blank + 1], interp::kBlankNeutralC);
}

// grey_short_mix's combined programs over the same day (the fourteenth round): at every control
// sample the control applies the plan plus the evaluator's mixed line (machine_eval/strategies.h
// MixedLines of the grey box and the base rule, both run causally): K0 and slope each
// w grey + (1 - w) rule, the grey box's blank term latched by the plan times w. A weight of
// 0.7 (the fitted one may be 1 on this short record, where the mix is the grey box's line, a
// case checked byte for byte below); the rule's part must show (else a program that dropped it
// would pass).
TEST(CombinedPrograms, ReplayAppliesPlanPlusTheMixedLineOfTheGreyBoxAndTheRule) {
  const machine_eval::ReportScrew& r = ShortCut();
  ASSERT_TRUE(r.mix_computed);
  ASSERT_FALSE(r.grey.blank_sensor.empty());
  ASSERT_TRUE(r.mix_rule.sensors.empty());
  ASSERT_GT(r.mix_rule.features(), 0);
  const double w = 0.7;
  const interp::MachineProfile profile =
      CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm);
  const CombinedPrograms p = BuildCombinedMixPrograms(
      r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm, r.plan_options, r.grey,
      r.mix_rule_offset, r.mix_rule_slope, w, profile, "test curve", "test mix");
  ASSERT_TRUE(p.mixed);
  const drift::Run& log = r.log;
  const machine_eval::HeldSamples grey = machine_eval::RunCausally(r.grey, log);
  const machine_eval::HeldSamples held =
      machine_eval::MixedLines(grey, machine_eval::RunCausally(r.mix_rule, log), w);
  const Eigen::MatrixXd grey_raw = drift::GreyBoxRawInputs(r.grey, log);
  const Eigen::MatrixXd rule_raw = drift::JointRawInputs(r.mix_rule, log);
  Eigen::MatrixXd raw(log.samples(), grey_raw.cols() + rule_raw.cols());
  raw << grey_raw, rule_raw;
  std::vector<std::string> inputs = r.grey.Inputs();
  inputs.insert(inputs.end(), r.mix_rule.other_inputs.begin(), r.mix_rule.other_inputs.end());
  const int blank = p.drift.blank_param;
  DayReplay day(r, p, raw, inputs);
  interp::replay::Replay& replay = day.replay;
  const double s = interp::SignFactor(p.plan.options.sign);
  day.PowerOn();
  if (::testing::Test::HasFatalFailure()) return;
  const int per_sample = SamplesPerInterval(log);
  const double g_b = r.grey.blank_um_per_1000_per_k;
  double worst_um = 0, rule_part_um = 0;
  int cut_samples = 0;
  for (int k = 1; k < log.samples(); ++k) {
    const auto [uk, t1, pos, cutting] = day.Step(k, per_sample);
    if (::testing::Test::HasFailure()) return;
    const double latch = replay.control.ac_param[blank + 1];
    const double blank_um = cutting ? w * g_b * (latch - 20.0) : 0.0;
    const double arm = (r.z_ref_mm - day.ZAt(t1)) / 1000.0;
    const double machine_um = held.k0_um[uk] + (held.slope_um_per_1000[uk] + blank_um) * arm;
    const double grey_um = grey.k0_um[uk] + (grey.slope_um_per_1000[uk] + blank_um / w) * arm;
    const double applied_um = replay.control.DkMm(pos) * 1000.0 / s;
    const double plan_um = cutting ? interp::AppliedCompensationUm(p.plan, pos) : 0.0;
    worst_um = std::max(worst_um, std::abs(applied_um - machine_um - plan_um));
    rule_part_um = std::max(rule_part_um, std::abs(machine_um - grey_um));
    cut_samples += cutting;
  }
  EXPECT_GT(cut_samples, 30);
  // Coefficients and weights print to 1e-10 mm (1e-4 nm): the replay agrees far below a nm.
  EXPECT_LT(worst_um, 1e-4);
  EXPECT_GT(rule_part_um, 0.1) << "the rule's 1 - w share must move the line";
  day.EndAndReset();
}

// The shop's path gives the lab report's program: the grey box and the rule written to a model
// file's mix part (drift/grey_box_io.h, what whirl drift fit-grey writes), read back and run as
// whirl drift nc runs it (interp::GreyMixComponents with the profile's drift options, reference
// model) give the drift program and the PLC table of BuildCombinedMixPrograms, byte for byte.
TEST(CombinedPrograms, TheShopsMixFileGivesTheLabReportsMixProgram) {
  const machine_eval::ReportScrew& r = ShortCut();
  const double w = 0.7;
  const interp::MachineProfile profile =
      CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm);
  const CombinedPrograms lab = BuildCombinedMixPrograms(
      r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm, r.plan_options, r.grey,
      r.mix_rule_offset, r.mix_rule_slope, w, profile, "test curve", "test mix");
  drift::GreyBoxMix part;
  part.weight = w;
  part.rule = r.mix_rule_name;
  part.rule_offset = r.mix_rule_offset;
  part.rule_slope = r.mix_rule_slope;
  const auto path = test::ScratchDir() / "shop_mix.json";
  drift::WriteGreyBoxFile(path, {r.grey, part});
  const drift::GreyBoxFile file = drift::ReadGreyBoxFile(path);
  ASSERT_TRUE(file.mix);
  const interp::GreyBoxAction grey = interp::GreyBoxActionModels(file.model);
  const std::vector<interp::DriftComponent> parts = interp::GreyMixComponents(
      grey, file.mix->rule_offset, file.mix->rule_slope, file.mix->weight);
  ASSERT_EQ(parts.size(), 2u);
  interp::DriftActionOptions options = profile.DriftOptions();
  options.reference = interp::DriftReference::kModel;
  EXPECT_EQ(interp::FormatDriftNcProgram(parts, options, "test mix"), lab.drift_nc);
  EXPECT_EQ(interp::FormatDriftPlcCsv(parts, options), lab.drift_plc_csv);
  EXPECT_EQ(interp::FormatDriftNcResetProgram(options), lab.drift_reset_nc);
  // The rule's 1 - w share shows in the program (a file that lost it would differ).
  EXPECT_NE(lab.drift_nc, BuildCombinedGreyPrograms(r.predicted_curve, r.kinematics,
                                                    r.result.screw.thread_length_mm,
                                                    r.plan_options, r.grey, profile,
                                                    "test curve", "test mix")
                              .drift_nc);
}

// w = 1 (a long record, or the guard's weight clamped to 1): the grey box's programs, byte for
// byte; a rule reading sensors, or a weight outside (0, 1], is refused.
TEST(CombinedPrograms, TheMixOfWeightOneIsTheGreyBoxsProgramsAndBadMixesAreRefused) {
  const machine_eval::ReportScrew& r = ShortCut();
  const interp::MachineProfile profile =
      CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm);
  auto mix = [&](double w, const drift::DriftModel& offset, const drift::DriftModel& slope) {
    return BuildCombinedMixPrograms(r.predicted_curve, r.kinematics,
                                    r.result.screw.thread_length_mm, r.plan_options, r.grey,
                                    offset, slope, w, profile, "c", "m");
  };
  const CombinedPrograms grey = BuildCombinedGreyPrograms(
      r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm, r.plan_options, r.grey,
      profile, "c", "m");
  const CombinedPrograms one = mix(1.0, r.mix_rule_offset, r.mix_rule_slope);
  EXPECT_FALSE(one.mixed);
  EXPECT_EQ(one.drift_nc, grey.drift_nc);
  EXPECT_EQ(one.drift_plc_csv, grey.drift_plc_csv);
  EXPECT_THROW(mix(0.0, r.mix_rule_offset, r.mix_rule_slope), InputError);
  EXPECT_THROW(mix(1.2, r.mix_rule_offset, r.mix_rule_slope), InputError);
  ASSERT_FALSE(r.sensor_model.sensors.empty());
  EXPECT_THROW(mix(0.7, r.offset, r.slope), InputError);  // both_shop's: sensors from power-on
}

TEST(CombinedPrograms, ProfileThatDisagreesWithTheMachineIsRefused) {
  const machine_eval::ReportScrew& r = ShortCut();
  interp::MachineProfile profile = CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm);
  EXPECT_NO_THROW(Build(r, profile));
  profile.drift->slope_fixed_end_mm += 10.0;  // the bearing is not where the machine has it
  EXPECT_THROW(Build(r, profile), InputError);
  profile = CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm);
  profile.drift->slope_growth_direction = 1;
  EXPECT_THROW(Build(r, profile), InputError);
  profile = CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm);
  profile.drift->workpiece_slope_param = -1;  // the plan would keep SD43910: two writers
  EXPECT_THROW(Build(r, profile), InputError);
  profile = CombinedProfile(-1, interp::ControlDk::kAdded, r.z_ref_mm);
  for (const std::string& in : r.sensor_model.sensors) profile.drift->inputs.erase(in);
  if (!r.sensor_model.sensors.empty()) {
    EXPECT_THROW(Build(r, profile), InputError);
  }
}

}  // namespace
}  // namespace whirl::machine_report
