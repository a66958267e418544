// The grey box (drift/grey_box.h) on the control: the drift action's NC program and the workpiece
// plan replayed cycle by cycle (tests/interp/nc_replay.h) against GreyBoxEvaluator, the
// reference: K0 and the slope every cycle, the blank estimate B latched by the plan at the
// thread start and held for the cut while B moves on, the latch back to 20 at the thread end, and
// the reset programs giving back what the control had. A hand-computed small example; bad
// inputs (an unmapped sensor, too few $AC_PARAM slots, no blank slot, reference start).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/error.h"
#include "drift/grey_box.h"
#include "fit/arctan_curve.h"
#include "interp/drift_action.h"
#include "interp/machine_profile.h"
#include "interp/nc_replay.h"
#include "interp/sinumerik.h"

namespace whirl::interp {
namespace grey_action_test {

constexpr double kCycleMs = 50.0;
constexpr double kFixedEndMm = 5587.5;  // P_b (MCS): z_ref = 6400 mm with the profile below

// Offset from t1, t2; slope from t2, t3; the blank from t3. Lags of 0.02 and 0.1 min and a blank
// lag of 0.05 min: a few hundred cycles of 50 ms, so every recursion is exercised.
// With `duty`: also a load (percent) on the offset and a speed (mm/min) on the slope, as logged
// with the same lags (the duty inputs of drift/grey_box.h).
drift::GreyBoxModel Model(bool duty = false) {
  drift::GreyBoxModel m;
  m.offset_sensors = {"t1_C", "t2_C"};
  m.slope_sensors = {"t2_C", "t3_C"};
  m.blank_sensor = "t3_C";
  m.time_constants = {0.02, 0.1};
  m.z_ref_mm = 6400;
  m.a.resize(6);
  m.a << 1.5, -2.5, 0.8, -0.6, 1.1, 0.4;
  m.g.resize(6);
  m.g << 4.0, 2.5, -1.0, 3.0, 1.5, 0.7;
  m.slope_intercept_um_per_1000 = 2.0;
  m.blank_tau_min = 0.05;
  m.blank_um_per_1000_per_k = -11.8;
  m.offset_min = m.slope_min = Eigen::VectorXd::Constant(6, -20.0);
  m.offset_max = m.slope_max = Eigen::VectorXd::Constant(6, 20.0);
  m.blank_min_c = 10;
  m.blank_max_c = 35;
  if (duty) {
    m.offset_duty = {"load_pct"};
    m.slope_duty = {"speed_mm_min"};
    m.a.conservativeResize(9);
    m.a.tail(3) << 0.05, 0.12, -0.03;
    m.g.conservativeResize(9);
    m.g.tail(3) << 0.02, -0.01, 0.04;
    for (Eigen::VectorXd* v : {&m.offset_min, &m.slope_min})
      v->conservativeResize(9), v->tail(3).setConstant(0.0);
    for (Eigen::VectorXd* v : {&m.offset_max, &m.slope_max})
      v->conservativeResize(9), v->tail(3).setConstant(200.0);
  }
  return m;
}

// The machine as the shipped field profile has it: travel -Z, the error and the growth towards
// the chuck (-1), the drift action owning SD43900-43920, the blank in $AC_PARAM[95], [96].
DriftActionOptions Options() {
  DriftActionOptions o;
  o.control_dk = ControlDk::kAdded;
  o.error_direction = -1;
  o.ipo_cycle_ms = kCycleMs;
  o.sync_id_first = 150;
  o.sync_id_last = 190;
  o.param_first = 100;
  o.save_r_first = 80;
  o.reference = DriftReference::kModel;
  o.has_slope = true;
  o.slope_fixed_end_mm = kFixedEndMm;
  o.slope_growth_direction = -1;
  o.workpiece_k0_param = 99;
  o.workpiece_slope_param = 97;
  o.blank_param = 95;
  o.inputs["t1_C"] = {3, 0.1, -20.0};
  o.inputs["t2_C"] = {7, 0.05, 0.0};
  o.inputs["t3_C"] = {9, 0.0625, 0.0};
  o.inputs["load_pct"] = {17, 0.1, 0.0};
  o.inputs["speed_mm_min"] = {18, 1.0, 0.0};
  return o;
}

PlanOptions Plan(const DriftActionOptions& d, bool latch) {
  PlanOptions p;
  p.direction = -1;
  p.sign = ExpectedSign(p.direction, p.control_dk);
  p.start_position_mm = 6200;  // thread start 6200 mm from the chuck face
  p.machine_offset_mm = -812.5;
  p.sync_id_first = 100;
  p.sync_id_last = 140;
  p.save_r_first = 90;
  p.workpiece_k0_param = d.workpiece_k0_param;
  p.workpiece_slope_param = d.workpiece_slope_param;
  p.drift_alive_param = d.param_first;
  p.blank_param = latch ? d.blank_param : -1;
  p.md32760 = kMd32760Max;
  return p;
}

// Inputs at cycle k: t1 warms, t2 creeps, t3 (the hall) falls by several K over the cut, so B
// moves by more than a K while the latched value must not [degC]; the load [%] steps every 40 s,
// the speed [mm/min] ramps.
using Inputs = Eigen::Matrix<double, 5, 1>;
Inputs Temperatures(int k) {
  const double t_s = k * kCycleMs / 1000.0;
  Inputs u;
  u << 25.0 + 6.0 * (1 - std::exp(-t_s / 20.0)), 26.0 + 0.08 * t_s,
      23.0 - 4.0 * (1 - std::exp(-t_s / 200.0)) + 0.3 * std::sin(t_s / 7.0),
      20.0 + 30.0 * (static_cast<int>(t_s / 40.0) % 3), 50.0 + 0.5 * t_s;
  return u;
}

void SetInputs(replay::Replay& r, const DriftActionOptions& o, const Inputs& t) {
  const char* names[] = {"t1_C", "t2_C", "t3_C", "load_pct", "speed_mm_min"};
  for (int i = 0; i < 5; ++i) {
    const AnalogInput& a = o.inputs.at(names[i]);
    r.control.ain[a.index] = (t(i) - a.offset) / a.scale;
  }
}

// The raw inputs the evaluator takes (GreyBoxRawInputs' order: t1, t2 | t2, t3 | t3, then the
// duty inputs load | speed).
Eigen::VectorXd Raw(const Inputs& t, bool duty = false) {
  Eigen::VectorXd u(duty ? 7 : 5);
  if (duty)
    u << t(0), t(1), t(1), t(2), t(2), t(3), t(4);
  else
    u << t(0), t(1), t(1), t(2), t(2);
  return u;
}

double Sign(const DriftActionOptions& o) {
  return (o.control_dk == ControlDk::kAdded ? -1.0 : 1.0) * o.error_direction;
}

double P(const replay::Replay& r, int n) {
  const auto it = r.control.ac_param.find(n);
  return it == r.control.ac_param.end() ? 0.0 : it->second;
}

// dK the control must apply at P: the plan's chord from its slots plus the machine line
// s/1000 (K0 + sigma G (P - P_b) / 1000), G the slope with the blank term of `latched_c`.
double ExpectedDkMm(const replay::Replay& r, const DriftActionOptions& o,
                    const drift::GreyBoxEvaluator& ev, const drift::GreyBoxEvaluator::Output& e,
                    double latched_c, double pos) {
  const double g = e.slope_um_per_1000 + ev.BlankSlope(latched_c);
  const double machine =
      Sign(o) / 1000.0 * (e.k0_um + o.slope_growth_direction * g * (pos - kFixedEndMm) / 1000.0);
  const double workpiece = P(r, 99) + P(r, 97) * (pos - P(r, 98));
  return workpiece + machine;
}

void FollowsTheEvaluator(bool duty) {
  const drift::GreyBoxModel model = Model(duty);
  const GreyBoxAction action = GreyBoxActionModels(model);
  const DriftActionOptions d = Options();
  const PlanOptions p = Plan(d, true);
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({20.0, 40.0}, 4.0, 1.0);
  const double feed = 2.0, thread = 300.0, t_end = thread / feed;
  const CompensationPlan plan = BuildPlan(curve, feed, thread, p);

  replay::Replay r;
  r.control.abs_value_mm = 0.0007;
  r.control.slope = 3e-6;
  r.control.ref_position_mm = 12.0;
  const double parked = AxisPositionMm(p, feed, 0.0) + 1.0;  // before the thread start (-Z)
  r.axis_mm = parked;
  drift::GreyBoxEvaluator ev(model);
  int k = 0;
  Inputs now = Temperatures(0);
  drift::GreyBoxEvaluator::Output e;
  auto step_reference = [&] { e = ev.Step(k * kCycleMs / 60000.0, Raw(now, duty)), ++k; };
  SetInputs(r, d, now);
  ASSERT_TRUE(
      r.RunProgram(FormatDriftNcProgram(action.offset, d, "", &action.slope, action.Blank())));
  EXPECT_EQ(P(r, 96), kBlankNeutralC);
  double worst_mm = 0;
  // A minute before the cut, axis parked: no blank term (the latch reads 20).
  while (k < 1200) {  // step_reference() advances k
    now = Temperatures(k);
    SetInputs(r, d, now);
    r.Cycle(parked);
    step_reference();
    worst_mm = std::max(worst_mm, std::abs(r.control.DkMm(parked) -
                                           ExpectedDkMm(r, d, ev, e, kBlankNeutralC, parked)));
  }
  EXPECT_LT(std::abs(P(r, 95) - e.blank_c), 1e-9);  // B runs as the evaluator's
  const std::string plan_nc = FormatNcProgram(plan);
  ASSERT_TRUE(r.RunProgram(plan_nc));
  for (std::size_t at = plan_nc.find("G4 "); at != std::string::npos;
       at = plan_nc.find("G4 ", at + 1))
    step_reference();  // the liveness dwell ran one cycle with the inputs as they were
  // B before each cycle: the evaluator's, and the control's own (what the plan copies).
  double latched = NAN, b_before = e.blank_c, b_control_before = P(r, 95);
  double latched_control = NAN, b_min = 1e9, b_max = -1e9, worst_if_unlatched = 0;
  const int cut_first = k;
  for (; (k - cut_first) * kCycleMs / 1000.0 <= t_end + 2.0;) {
    const double t_s = (k - cut_first) * kCycleMs / 1000.0;
    const double pos = AxisPositionMm(p, feed, std::min(t_s, t_end)) - (t_s > t_end ? 1.0 : 0.0);
    now = Temperatures(k);
    SetInputs(r, d, now);
    r.Cycle(pos);
    step_reference();
    const bool cutting = t_s < t_end;  // at the thread end the plan's restore has fired
    if (k - 1 == cut_first) {          // the plan copied B of the cycle before
      latched = b_before;
      latched_control = b_control_before;
      EXPECT_LT(std::abs(latched_control - latched), 1e-9);
    }
    if (cutting) {
      EXPECT_EQ(P(r, 96), latched_control) << "cycle " << k;
      b_min = std::min(b_min, e.blank_c);
      b_max = std::max(b_max, e.blank_c);
      worst_if_unlatched =
          std::max(worst_if_unlatched,
                   std::abs(r.control.DkMm(pos) - ExpectedDkMm(r, d, ev, e, e.blank_c, pos)));
    } else {
      EXPECT_EQ(P(r, 96), kBlankNeutralC) << "the thread end writes the latch back";
    }
    worst_mm = std::max(
        worst_mm, std::abs(r.control.DkMm(pos) -
                           ExpectedDkMm(r, d, ev, e, cutting ? latched : kBlankNeutralC, pos)));
    b_before = e.blank_c;
    b_control_before = P(r, 95);
  }
  EXPECT_LT(worst_mm, 1e-8);
  EXPECT_GT(b_max - b_min, 1.0) << "B must move during the cut for the latch to matter";
  EXPECT_GT(worst_if_unlatched, 1e-4) << "B now instead of the latch would be seen";
  // Reset programs: the control as found, the latch neutral.
  r.EndProgram();
  ASSERT_TRUE(r.RunProgram(FormatNcResetProgram(p)));
  EXPECT_EQ(P(r, 96), kBlankNeutralC);
  ASSERT_TRUE(r.RunProgram(FormatDriftNcResetProgram(d)));
  EXPECT_EQ(r.control.abs_value_mm, 0.0007);
  EXPECT_EQ(r.control.slope, 3e-6);
  EXPECT_EQ(r.control.ref_position_mm, 12.0);
  EXPECT_TRUE(r.actions.empty());
}

TEST(GreyAction, TheControlFollowsTheEvaluatorAndHoldsTheLatchedBlankForTheCut) {
  FollowsTheEvaluator(false);
}

// Duty inputs (the ring's load on K0, the Z speed on the slope) are read as logged, without a
// reference, through their own lags: the control still equals the evaluator every cycle.
TEST(GreyAction, DutyInputsAreEvaluatedAsFitted) { FollowsTheEvaluator(true); }

// An aborted cut leaves the latch set: the plan's next call (its undo) and its reset program
// write 20 back before anything else, so the approach applies no blank term.
TEST(GreyAction, AnAbortedCutsLatchIsWrittenBack) {
  const GreyBoxAction action = GreyBoxActionModels(Model());
  const DriftActionOptions d = Options();
  const PlanOptions p = Plan(d, true);
  const CompensationPlan plan =
      BuildPlan(fit::ArctanCurve::FromFeatures({20.0, 40.0}, 4.0, 1.0), 2.0, 300.0, p);
  for (bool by_reset : {false, true}) {
    replay::Replay r;
    const double parked = AxisPositionMm(p, 2.0, 0.0) + 1.0;
    r.axis_mm = parked;
    SetInputs(r, d, Temperatures(0));
    ASSERT_TRUE(
        r.RunProgram(FormatDriftNcProgram(action.offset, d, "", &action.slope, action.Blank())));
    ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan)));
    for (int k = 0; k < 400; ++k) r.Cycle(AxisPositionMm(p, 2.0, 0.05 * k));  // into the cut
    ASSERT_NE(P(r, 96), kBlankNeutralC);
    r.EndProgram();  // aborted: the thread end never came
    r.axis_mm = parked;
    if (by_reset) {
      ASSERT_TRUE(r.RunProgram(FormatNcResetProgram(p)));
    } else {  // called again: its undo of the aborted run (the drift program does not rerun)
      ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan)));
    }
    EXPECT_EQ(P(r, 96), kBlankNeutralC) << (by_reset ? "reset" : "rerun");
  }
}

// A plan that does not latch refuses to start beside an action that reads the latch (mode 3):
// its slope would miss the blank term; a latching plan runs beside an action without one.
TEST(GreyAction, APlanThatDoesNotLatchRefusesAnActionThatReadsTheLatch) {
  const GreyBoxAction action = GreyBoxActionModels(Model());
  const DriftActionOptions d = Options();
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({20.0, 40.0}, 4.0, 1.0);
  const CompensationPlan no_latch = BuildPlan(curve, 2.0, 300.0, Plan(d, false));
  const CompensationPlan latch = BuildPlan(curve, 2.0, 300.0, Plan(d, true));
  replay::Replay r;
  r.axis_mm = AxisPositionMm(no_latch.options, 2.0, 0.0) + 1.0;
  SetInputs(r, d, Temperatures(0));
  ASSERT_TRUE(
      r.RunProgram(FormatDriftNcProgram(action.offset, d, "", &action.slope, action.Blank())));
  EXPECT_FALSE(r.RunProgram(FormatNcProgram(no_latch)));
  EXPECT_EQ(r.control.alarm, no_latch.options.drift_missing_alarm + 2);
  EXPECT_TRUE(r.RunProgram(FormatNcProgram(latch)));
  // The same latching plan beside a slope action without a blank term (mode 2) runs too.
  replay::Replay q;
  q.axis_mm = r.axis_mm;
  SetInputs(q, d, Temperatures(0));
  ASSERT_TRUE(q.RunProgram(FormatDriftNcProgram(action.offset, d, "", &action.slope)));
  EXPECT_TRUE(q.RunProgram(FormatNcProgram(latch)));
}

// By hand: no lags; T1 = 25, T2 = 22, T3 = 18 degC held. K0 = 2 (25 - 20) = 10 um; G = 3 +
// 4 (22 - 20) = 11 um per 1000 mm, and with B = 18 latched -11.8 (18 - 20) = 23.6 more: 34.6.
// s = +1 (dK added, error towards -Z), sigma = -1: S_m = -G / 1e6, K_m = K0 / 1000 mm; no plan,
// the part program latches by hand as the header says.
TEST(GreyAction, HandComputedSmallExample) {
  drift::GreyBoxModel m;
  m.offset_sensors = {"t1_C"};
  m.slope_sensors = {"t2_C"};
  m.blank_sensor = "t3_C";
  m.a = Eigen::VectorXd::Constant(1, 2.0);
  m.g = Eigen::VectorXd::Constant(1, 4.0);
  m.slope_intercept_um_per_1000 = 3.0;
  m.blank_tau_min = 30;
  m.blank_um_per_1000_per_k = -11.8;
  m.offset_min = m.slope_min = Eigen::VectorXd::Constant(1, -10.0);
  m.offset_max = m.slope_max = Eigen::VectorXd::Constant(1, 10.0);
  m.blank_min_c = 15;
  m.blank_max_c = 25;
  const GreyBoxAction a = GreyBoxActionModels(m);
  const DriftActionOptions d = Options();
  replay::Replay r;
  Inputs hand;
  hand << 25.0, 22.0, 18.0, 0.0, 0.0;
  SetInputs(r, d, hand);
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(a.offset, d, "", &a.slope, a.Blank())));
  for (int k = 0; k < 10; ++k) r.Cycle(0.0);
  EXPECT_NEAR(r.control.slope, -11e-6, 1e-13);
  EXPECT_NEAR(r.control.ref_position_mm, kFixedEndMm, 1e-9);
  EXPECT_NEAR(r.control.abs_value_mm, 0.010, 1e-12);
  EXPECT_NEAR(P(r, 95), 18.0, 1e-12);
  r.control.ac_param[96] = P(r, 95);  // STOPRE, $AC_PARAM[96]=$AC_PARAM[95]
  r.Cycle(0.0);
  EXPECT_NEAR(r.control.slope, -34.6e-6, 1e-13);
  EXPECT_NEAR(r.control.abs_value_mm, 0.010, 1e-12);
  // The bound MD32760 must cover: |3| + 4 x 10 + 11.8 x max(|15 - 20|, |25 - 20|) = 102 um per
  // 1000 mm = 1.02e-4.
  EXPECT_NEAR(DriftSlopeBound(a.slope, d, a.Blank()), 1.02e-4, 1e-13);
  // The PLC table carries the blank row with c_b = s sigma g_b / 1e6 = +1.18e-5 per K.
  const std::string csv = FormatDriftPlcCsv(a.offset, d, &a.slope, a.Blank());
  EXPECT_NE(csv.find("slope,blank_latched,t3_C,9,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",0.00001180000000\n"), std::string::npos) << csv;
}

void ExpectRefused(const std::function<void()>& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no error, expected one naming '" << needle << "'";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// A grey box as large as the field's every-sensor one (13 sensors on both channels, 2 lags, the
// blank term; no plan, so the latch stays neutral and the workpiece slots 0): its rises, lag starts and lag updates are
// packed several to an action and over several actions each (every line within the control's
// 512 characters); the control still equals the evaluator every cycle, K0 and slope.
TEST(GreyAction, ALargeGreyBoxPackedIntoFewActionsFollowsTheEvaluator) {
  constexpr int kSensors = 13;
  drift::GreyBoxModel m;
  for (int i = 0; i < kSensors; ++i) m.offset_sensors.push_back("s" + std::to_string(i) + "_C");
  m.slope_sensors = m.offset_sensors;
  m.blank_sensor = m.offset_sensors[0];
  m.time_constants = {0.02, 0.1};
  const int n = kSensors * 3;
  m.a.resize(n);
  m.g.resize(n);
  for (int j = 0; j < n; ++j) m.a(j) = 0.6 * std::sin(j + 1.0), m.g(j) = 0.4 * std::cos(j + 0.5);
  m.slope_intercept_um_per_1000 = 1.5;
  m.blank_tau_min = 0.05;
  m.blank_um_per_1000_per_k = -11.8;
  m.offset_min = m.slope_min = Eigen::VectorXd::Constant(n, -20.0);
  m.offset_max = m.slope_max = Eigen::VectorXd::Constant(n, 20.0);
  const GreyBoxAction action = GreyBoxActionModels(m);
  DriftActionOptions d = Options();
  for (int i = 0; i < kSensors; ++i) d.inputs[m.offset_sensors[i]] = {i + 1, 0.0625, 0.0};
  const std::string nc =
      FormatDriftNcProgram(action.offset, d, "", &action.slope, action.Blank());
  // One action per input's rise and per input's lags would need 2 x 13 x 2 alone.
  int ids = 0, packed_rises = 0, lag_starts = 0;
  std::istringstream in(nc);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("IDS=", 0) != 0) continue;
    ++ids;
    std::size_t reads = 0;
    for (std::size_t at = line.find("$A_INA["); at != std::string::npos;
         at = line.find("$A_INA[", at + 1))
      ++reads;
    packed_rises += reads > 1;
    lag_starts += line.find("WHENEVER") != std::string::npos;
    EXPECT_LE(line.size(), 512u);
  }
  EXPECT_LE(ids, d.sync_id_last - d.sync_id_first + 1);
  EXPECT_GE(packed_rises, 2);
  EXPECT_GE(lag_starts, 5);  // per channel: the lags' start over 2 actions; B's own
  replay::Replay r;
  const double parked = 4000.0;
  drift::GreyBoxEvaluator ev(m);
  auto temperature = [](int i, double t_s) {
    return 18.0 + i + 4.0 * (1 - std::exp(-t_s / (10.0 + 3 * i))) + 0.3 * std::sin(t_s / (3.0 + i));
  };
  Eigen::VectorXd raw(2 * kSensors + 1);
  auto set = [&](int k) {
    const double t_s = k * kCycleMs / 1000.0;
    for (int i = 0; i < kSensors; ++i) {
      const double t = temperature(i, t_s);
      r.control.ain[i + 1] = t / 0.0625;
      raw(i) = raw(kSensors + i) = t;
    }
    raw(2 * kSensors) = raw(0);
  };
  set(0);
  ASSERT_TRUE(r.RunProgram(nc));
  double worst_mm = 0, largest_mm = 0;
  for (int k = 0; k < 1500; ++k) {
    set(k);
    r.Cycle(parked);
    const drift::GreyBoxEvaluator::Output e = ev.Step(k * kCycleMs / 60000.0, raw);
    const double expected = ExpectedDkMm(r, d, ev, e, kBlankNeutralC, parked);
    worst_mm = std::max(worst_mm, std::abs(r.control.DkMm(parked) - expected));
    largest_mm = std::max(largest_mm, std::abs(expected));
  }
  EXPECT_LT(worst_mm, 1e-8);
  EXPECT_GT(largest_mm, 1e-3);  // the comparison sees a model that moves
}

TEST(GreyAction, BadInputsAreRefusedWithTheirReason) {
  const GreyBoxAction a = GreyBoxActionModels(Model());
  auto program = [&](const DriftActionOptions& d) {
    return [&a, d] { (void)FormatDriftNcProgram(a.offset, d, "", &a.slope, a.Blank()); };
  };
  DriftActionOptions d = Options();
  d.inputs.erase("t3_C");  // the blank (and slope) sensor has no analog input
  ExpectRefused(program(d), "no analog input mapped for the model's input 't3_C'");
  d = Options();
  d.param_last = 110;  // the slots of the two models, S_m and B's flag do not fit
  ExpectRefused(program(d), "drift.param_last");
  d = Options();
  d.control = {18, 400, 100};  // MD28254: $AC_PARAM[0..99]; the latch would be [101]
  d.param_first = 10;
  d.blank_param = 100;
  ExpectRefused(program(d), "slot 101 does not exist: MD28254");
  d = Options();
  d.blank_param = -1;
  ExpectRefused(program(d), "drift.blank_param");
  d = Options();
  d.reference = DriftReference::kStart;
  ExpectRefused(program(d), "reference 'model'");
  d = Options();
  d.blank_param = 101;  // inside the action's own slots
  ExpectRefused(program(d), "own $AC_PARAM slots");
  d = Options();
  d.blank_param = 98;  // the latch would be the plan's SD43920 slot
  ExpectRefused([&] { d.Validate(); }, "blank_param");
  // MD28254 accounted in the requirements: the latch slot counts.
  d = Options();
  d.param_first = 10;
  for (const ControlRequirement& q : DriftRequirements(a.offset, d, &a.slope, a.Blank()))
    if (q.datum.rfind("MD28254", 0) == 0) {
      EXPECT_EQ(q.value, 97.0);
    }
  // The profile's slot pair: not in the drift action's own range, not a workpiece slot.
  MachineProfile profile =
      LoadMachineProfile(std::string(WHIRL_SOURCE_DIR) + "/datasets/machines/whirling_840d.json");
  EXPECT_EQ(profile.drift->blank_param, 95);
  profile.drift->blank_param = 100;
  ExpectRefused([&] { profile.Validate(); },
                "drift.blank_param 100 lies in the drift action's own");
  profile.drift->blank_param = 96;
  ExpectRefused([&] { profile.Validate(); }, "blank_param 96");
  // A grey box without an offset sensor cannot be a drift action.
  drift::GreyBoxModel no_offset = Model();
  no_offset.offset_sensors.clear();
  no_offset.a.resize(0);
  no_offset.offset_min.resize(0);
  no_offset.offset_max.resize(0);
  ExpectRefused([&] { (void)GreyBoxActionModels(no_offset); }, "offset sensor");
}

}  // namespace grey_action_test
}  // namespace whirl::interp
