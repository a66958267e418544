// The live drift action replayed as the control runs it (tests/interp/nc_replay.h): SD43900
// follows the drift model evaluated sample by sample (drift::DriftEvaluator, the reference), for
// static and lagged models and both temperature references; combined with a whirling plan, one
// writer owns SD43900 and it equals machine part + workpiece part; the reset programs restore.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "drift/model.h"
#include "fit/arctan_curve.h"
#include "interp/drift_action.h"
#include "interp/nc_replay.h"
#include "interp/sinumerik.h"
#include "support/rfc4180.h"

namespace whirl::interp {
namespace {

constexpr double kCycleMs = 50.0;

// A hand-made model: two sensors, lags of 0.02 and 0.1 min (a few hundred cycles of 50 ms, so
// the lag recursion is exercised), the given coefficients (intercept um, then um per K for each
// sensor's direct rise and its lags, sensor by sensor).
drift::DriftModel HandModel(bool lags, const std::vector<double>& coefficients) {
  drift::DriftModel m;
  m.kind = lags ? drift::ModelKind::kDynamic : drift::ModelKind::kMlr;
  m.error_column = "ch1_um";
  m.sensors = {"t1_C", "t2_C"};
  m.reference_C = Eigen::Vector2d(24.5, 26.25);
  if (lags) m.time_constants = {0.02, 0.1};
  for (const auto& s : m.sensors) {
    m.features.push_back({s, 0.0});
    for (double t : m.time_constants) m.features.push_back({s, t});
  }
  const auto nf = static_cast<Eigen::Index>(m.features.size());
  m.feature_min = Eigen::VectorXd::Constant(nf, -5);
  m.feature_max = Eigen::VectorXd::Constant(nf, 5);
  if (static_cast<Eigen::Index>(coefficients.size()) != nf + 1)
    throw std::invalid_argument("HandModel: coefficient count");
  m.linear.coefficients = Eigen::Map<const Eigen::VectorXd>(coefficients.data(), nf + 1);
  m.linear.covariance = Eigen::MatrixXd::Identity(nf + 1, nf + 1) * 0.01;
  m.Validate();
  return m;
}

// The same with coefficients of a typical size (um per K) drawn uniformly within +-8 (for the
// replay tests, which compare with the model itself; the golden files use fixed coefficients).
drift::DriftModel HandModel(bool lags, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-8.0, 8.0);
  std::vector<double> c(lags ? 7 : 3);
  for (double& v : c) v = u(rng);
  return HandModel(lags, c);
}

DriftActionOptions Options(ControlDk control, int error_direction, DriftReference ref) {
  DriftActionOptions o;
  o.axis = "Z";
  o.control_dk = control;
  o.error_direction = error_direction;
  o.ipo_cycle_ms = kCycleMs;
  o.sync_id_first = 150;
  o.sync_id_last = 190;
  o.param_first = 100;
  o.save_r_first = 80;
  o.reference = ref;
  o.inputs["t1_C"] = {3, 0.1, -20.0};  // T = 0.1 * AIN + (-20)
  o.inputs["t2_C"] = {7, 0.05, 0.0};
  return o;
}

// Temperatures at cycle k: smooth warm-ups with different rates.
Eigen::Vector2d Temperatures(int k) {
  const double t_s = k * kCycleMs / 1000.0;
  return Eigen::Vector2d(25.0 + 6.0 * (1 - std::exp(-t_s / 20.0)), 26.0 + 0.08 * t_s);
}

void SetInputs(replay::Replay& r, const DriftActionOptions& o, const Eigen::Vector2d& t) {
  r.control.ain[o.inputs.at("t1_C").index] =
      (t(0) - o.inputs.at("t1_C").offset) / o.inputs.at("t1_C").scale;
  r.control.ain[o.inputs.at("t2_C").index] =
      (t(1) - o.inputs.at("t2_C").offset) / o.inputs.at("t2_C").scale;
}

double Sign(const DriftActionOptions& o) {
  return (o.control_dk == ControlDk::kAdded ? -1.0 : 1.0) * o.error_direction;
}

TEST(DriftAction, Sd43900FollowsTheModelEvaluatedSampleBySample) {
  std::mt19937 rng(1804);
  for (bool lags : {false, true})
    for (auto control : {ControlDk::kAdded, ControlDk::kSubtracted})
      for (int dir : {1, -1})
        for (auto ref : {DriftReference::kModel, DriftReference::kStart}) {
          const drift::DriftModel m = HandModel(lags, rng);
          const DriftActionOptions o = Options(control, dir, ref);
          replay::Replay r;
          r.control.abs_value_mm = 0.0021;
          SetInputs(r, o, Temperatures(0));
          ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, o)));
          const Eigen::VectorXd reference =
              ref == DriftReference::kModel ? m.reference_C : Eigen::VectorXd(Temperatures(0));
          drift::DriftEvaluator ev(m, reference);
          double worst_mm = 0;
          for (int k = 0; k < 1500; ++k) {
            SetInputs(r, o, Temperatures(k));
            r.Cycle(0.0);
            const double e_um = ev.Step(k * kCycleMs / 60000.0, Temperatures(k));
            worst_mm =
                std::max(worst_mm, std::abs(r.control.abs_value_mm - Sign(o) * e_um / 1000.0));
          }
          EXPECT_LT(worst_mm, 1e-8) << "lags " << lags << " ref " << ToString(ref);
          ASSERT_FALSE(HasFailure());
          // Static actions survive the program's end; the reset program restores SD43900.
          r.EndProgram();
          EXPECT_FALSE(r.actions.empty());
          ASSERT_TRUE(r.RunProgram(FormatDriftNcResetProgram(o)));
          EXPECT_TRUE(r.actions.empty());
          EXPECT_EQ(r.control.abs_value_mm, 0.0021);
        }
}

// A model with elapsed-time warm-up terms (drift fit's time1, time2, sensors+time): the given
// sensors (none: time-only) without lags, then elapsed lags of `taus` [min]; coefficients
// intercept, per sensor, per elapsed term.
drift::DriftModel ElapsedModel(const std::vector<std::string>& sensors,
                               const std::vector<double>& taus,
                               const std::vector<double>& coefficients) {
  drift::DriftModel m;
  m.error_column = "ch1_um";
  m.sensors = sensors;
  m.reference_C = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(sensors.size()), 25.0);
  m.elapsed_time_constants = taus;
  for (const auto& s : m.sensors) m.features.push_back({s, 0.0});
  for (double t : taus) m.features.push_back({"elapsed", t});
  const auto nf = static_cast<Eigen::Index>(m.features.size());
  m.feature_min = Eigen::VectorXd::Constant(nf, -5);
  m.feature_max = Eigen::VectorXd::Constant(nf, 5);
  m.linear.coefficients = Eigen::Map<const Eigen::VectorXd>(coefficients.data(), nf + 1);
  m.linear.covariance = Eigen::MatrixXd::Identity(nf + 1, nf + 1) * 0.01;
  m.Validate();
  return m;
}

// Elapsed time is counted by the actions themselves from the program's start: SD43900 follows the
// evaluator (x = 0 at the start, 1 - exp(-t / tau) after) for one and two terms and beside
// sensors, both references; the PLC table's rows rebuild the same value from a_per_cycle; no
// analog input is asked for "elapsed" (issue 45: the lookup ran past the model's inputs).
TEST(DriftAction, ElapsedTimeIsCountedByTheControl) {
  const std::vector<drift::DriftModel> models{
      ElapsedModel({}, {0.05}, {0.4, 6.0}),
      ElapsedModel({}, {0.02, 0.1}, {-0.3, 4.0, 2.5}),
      ElapsedModel({"t1_C", "t2_C"}, {0.07}, {0.2, 1.5, -0.8, 3.0})};
  for (const drift::DriftModel& m : models)
    for (auto ref : {DriftReference::kModel, DriftReference::kStart}) {
      DriftActionOptions o = Options(ControlDk::kAdded, 1, ref);
      if (m.sensors.empty()) o.inputs.clear();
      replay::Replay r;
      SetInputs(r, Options(ControlDk::kAdded, 1, ref), Temperatures(0));
      const std::string nc = FormatDriftNcProgram(m, o);
      ASSERT_TRUE(r.RunProgram(nc)) << nc;
      const Eigen::VectorXd reference =
          ref == DriftReference::kModel || m.sensors.empty() ? m.reference_C
                                                             : Eigen::VectorXd(Temperatures(0));
      drift::DriftEvaluator ev(m, reference);
      double worst_mm = 0;
      for (int k = 0; k < 1500; ++k) {  // 1.25 min: 25 of the shortest time constant
        SetInputs(r, Options(ControlDk::kAdded, 1, ref), Temperatures(k));
        r.Cycle(0.0);
        const Eigen::VectorXd raw = m.sensors.empty() ? Eigen::VectorXd() : Eigen::VectorXd(Temperatures(k));
        const double e_um = ev.Step(k * kCycleMs / 60000.0, raw);
        worst_mm = std::max(worst_mm, std::abs(r.control.abs_value_mm - Sign(o) * e_um / 1000.0));
      }
      EXPECT_LT(worst_mm, 1e-8) << m.sensors.size() << " sensors, " << ToString(ref) << "\n" << nc;
      // The PLC table: an elapsed row reads no input; its a_per_cycle rebuilds 1 - exp(-t/tau).
      std::istringstream csv(FormatDriftPlcCsv(m, o));
      std::string line;
      int elapsed_rows = 0;
      while (std::getline(csv, line)) {
        if (line.rfind("k0_mm,elapsed_lag", 0) != 0) continue;
        ++elapsed_rows;
        std::vector<std::string> cell;
        std::stringstream ls(line);
        for (std::string c; std::getline(ls, c, ',');) cell.push_back(c);
        ASSERT_EQ(cell.size(), 10u) << line;
        EXPECT_EQ(cell[2], "elapsed");
        EXPECT_EQ(cell[3], "") << "no analog input for elapsed time";
        const double tau = std::stod(cell[7]), a = std::stod(cell[8]);
        double x = 0;
        for (int k = 0; k < 600; ++k) x += a * (1 - x);
        EXPECT_NEAR(x, 1 - std::exp(-600 * kCycleMs / 60000.0 / tau), 1e-9) << line;
      }
      EXPECT_EQ(elapsed_rows, static_cast<int>(m.elapsed_time_constants.size()));
    }
}

// A model of 8 sensors with a lag each (16 features, the simulated machine's default fit of
// issue 45): the sum no longer fits one line of 512 characters, so it is accumulated over several
// actions; SD43900 still follows the evaluator.
TEST(DriftAction, LongModelsSumOverSeveralActions) {
  drift::DriftModel m;
  m.kind = drift::ModelKind::kDynamic;
  m.error_column = "offset_um";
  m.time_constants = {0.05};
  DriftActionOptions o = Options(ControlDk::kAdded, 1, DriftReference::kStart);
  o.inputs.clear();
  std::vector<double> c{0.7};
  for (int i = 0; i < 8; ++i) {
    const std::string name = "s" + std::to_string(i) + "_C";
    m.sensors.push_back(name);
    m.features.push_back({name, 0.0});
    m.features.push_back({name, 0.05});
    o.inputs[name] = {i + 1, 0.0625, 0.0};
    c.push_back(123.4567 * (i % 2 ? -1 : 1) / (i + 1));
    c.push_back(-45.678 / (i + 1));
  }
  m.reference_C = Eigen::VectorXd::Constant(8, 20.0);
  m.feature_min = Eigen::VectorXd::Constant(16, -5);
  m.feature_max = Eigen::VectorXd::Constant(16, 5);
  m.linear.coefficients = Eigen::Map<const Eigen::VectorXd>(c.data(), 17);
  m.linear.covariance = Eigen::MatrixXd::Identity(17, 17) * 0.01;
  m.Validate();
  auto temps = [](int k) {
    Eigen::VectorXd t(8);
    for (int i = 0; i < 8; ++i) t(i) = 20 + (i + 1) * (1 - std::exp(-k * kCycleMs / 1000.0 / (5.0 + 3 * i)));
    return t;
  };
  const std::string nc = FormatDriftNcProgram(m, o);
  std::istringstream lines(nc);
  for (std::string line; std::getline(lines, line);) EXPECT_LE(line.size(), 512u) << line;
  replay::Replay r;
  auto set = [&](const Eigen::VectorXd& t) {
    for (int i = 0; i < 8; ++i) r.control.ain[i + 1] = t(i) / 0.0625;
  };
  set(temps(0));
  ASSERT_TRUE(r.RunProgram(nc)) << nc;
  drift::DriftEvaluator ev(m, temps(0));
  double worst_mm = 0;
  for (int k = 0; k < 600; ++k) {
    set(temps(k));
    r.Cycle(0.0);
    const double e_um = ev.Step(k * kCycleMs / 60000.0, temps(k));
    worst_mm = std::max(worst_mm, std::abs(r.control.abs_value_mm - Sign(o) * e_um / 1000.0));
  }
  EXPECT_LT(worst_mm, 1e-8) << nc;
}

TEST(DriftAction, CombinedWithAPlanOneWriterAddsBothParts) {
  std::mt19937 rng(1805);
  const drift::DriftModel m = HandModel(true, rng);
  DriftActionOptions d = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  d.workpiece_k0_param = 99;
  PlanOptions p;
  p.start_position_mm = 0;
  p.machine_offset_mm = -600;
  p.sync_id_first = 100;  // below the drift action's 150..190: written before it is added
  p.sync_id_last = 140;
  p.save_r_first = 90;
  p.workpiece_k0_param = 99;
  p.drift_alive_param = d.param_first;
  p.md32760 = kMd32760Max;
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({20.0, 40.0}, 4.0, 1.0);
  const double feed = 2.0, thread = 300.0;  // 150 s of cutting
  const CompensationPlan plan = BuildPlan(curve, feed, thread, p);

  replay::Replay r;
  r.control.abs_value_mm = 0.0007;  // found values
  r.control.slope = 3e-6;
  r.control.ref_position_mm = 12.0;
  r.axis_mm = AxisPositionMm(p, feed, 0.0) - 1.0;  // parked before the thread start
  // Without the drift action the plan refuses to start, and changes nothing.
  EXPECT_FALSE(r.RunProgram(FormatNcProgram(plan)));
  EXPECT_EQ(r.control.alarm, p.drift_missing_alarm);
  EXPECT_EQ(r.control.slope, 3e-6);
  EXPECT_TRUE(r.actions.empty());

  SetInputs(r, d, Temperatures(0));
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, d)));
  ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan)));
  drift::DriftEvaluator ev(m, m.reference_C);
  const int cycles = static_cast<int>(thread / feed * 1000.0 / kCycleMs);
  double worst_um = 0;
  for (int k = 0; k <= cycles + 40; ++k) {
    const double t_s = k * kCycleMs / 1000.0;
    const double pos = AxisPositionMm(p, feed, std::min(t_s, thread / feed)) +
                       (t_s > thread / feed ? 1.0 : 0.0);  // run-out past the thread end
    SetInputs(r, d, Temperatures(k));
    r.Cycle(pos);
    const double machine_mm = -ev.Step(t_s / 60.0, Temperatures(k)) / 1000.0;
    if (t_s >= thread / feed) {  // restored: machine part only, the found slope and reference
      EXPECT_NEAR(r.control.abs_value_mm, machine_mm, 1e-8);
      continue;
    }
    const double workpiece_um = (r.control.DkMm(pos) - machine_mm) * 1000.0 / SignFactor(p.sign);
    worst_um = std::max(worst_um, std::abs(workpiece_um - curve.ElongationUm(t_s)));
  }
  EXPECT_LE(worst_um, p.tolerance_um + 1e-6);
  EXPECT_EQ(r.control.slope, 3e-6);
  EXPECT_EQ(r.control.ref_position_mm, 12.0);
  r.EndProgram();
  ASSERT_TRUE(r.RunProgram(FormatDriftNcResetProgram(d)));
  EXPECT_EQ(r.control.abs_value_mm, 0.0007);
  EXPECT_TRUE(r.actions.empty());
}

// The slope channel of a screw growing from its fixed end: um per 1000 mm, from two sensors.
drift::DriftModel SlopeModel() {
  drift::DriftModel g = HandModel(false, {0.8, 11.5, -3.0});  // ~ 11.5 um per metre per K
  g.error_column = "zscrew_per_1000_um";
  return g;
}

DriftActionOptions SlopeOptions(ControlDk control, int error_direction, int sigma) {
  DriftActionOptions o = Options(control, error_direction, DriftReference::kModel);
  o.has_slope = true;
  o.slope_fixed_end_mm = 5587.5;
  o.slope_growth_direction = sigma;
  return o;
}

// Machine alone: dK(P) = s/1000 (e_K + sigma g (P - P_b) / 1000) at every position, every cycle.
TEST(DriftAction, SlopeModeWritesTheMachineLineAboutTheFixedEnd) {
  std::mt19937 rng(1810);
  for (auto control : {ControlDk::kAdded, ControlDk::kSubtracted})
    for (int dir : {1, -1})
      for (int sigma : {1, -1}) {
        const drift::DriftModel m = HandModel(true, rng), g = SlopeModel();
        const DriftActionOptions o = SlopeOptions(control, dir, sigma);
        replay::Replay r;
        r.control.abs_value_mm = 0.0021;  // found values
        r.control.slope = -4e-6;
        r.control.ref_position_mm = 33.0;
        SetInputs(r, o, Temperatures(0));
        ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, o, "", &g)));
        drift::DriftEvaluator ev_k(m, m.reference_C), ev_g(g, g.reference_C);
        double worst_mm = 0;
        for (int k = 0; k < 1200; ++k) {
          SetInputs(r, o, Temperatures(k));
          r.Cycle(0.0);
          const double t_min = k * kCycleMs / 60000.0;
          const double e_k = ev_k.Step(t_min, Temperatures(k)),
                       e_g = ev_g.Step(t_min, Temperatures(k));
          for (double p : {-812.5, 0.0, 2500.0, 5587.5, 6400.0}) {
            const double expected = Sign(o) / 1000.0 * (e_k + sigma * e_g * (p - 5587.5) / 1000.0);
            worst_mm = std::max(worst_mm, std::abs(r.control.DkMm(p) - expected));
          }
        }
        EXPECT_LT(worst_mm, 1e-8) << "sigma " << sigma << " dir " << dir;
        EXPECT_EQ(r.control.ref_position_mm, 5587.5);
        r.EndProgram();
        ASSERT_TRUE(r.RunProgram(FormatDriftNcResetProgram(o)));
        EXPECT_TRUE(r.actions.empty());
        EXPECT_EQ(r.control.abs_value_mm, 0.0021);
        EXPECT_EQ(r.control.slope, -4e-6);
        EXPECT_EQ(r.control.ref_position_mm, 33.0);
        ASSERT_FALSE(HasFailure());
      }
}

// Plan and machine both with slopes: the drift action is the only writer of SD43900-43920 and the
// control applies workpiece plan + machine line at every position of the cut.
TEST(DriftAction, SlopeHandedOverTheSumOfBothLinesHoldsEverywhere) {
  std::mt19937 rng(1811);
  const drift::DriftModel m = HandModel(true, rng), g = SlopeModel();
  DriftActionOptions d = SlopeOptions(ControlDk::kAdded, -1, -1);
  d.workpiece_k0_param = 99;
  d.workpiece_slope_param = 97;
  PlanOptions p;
  p.direction = -1;
  p.sign = ExpectedSign(p.direction, p.control_dk);
  p.start_position_mm = 6200;  // thread start 6200 mm from the chuck face, travelling -Z
  p.machine_offset_mm = -812.5;
  p.sync_id_first = 100;
  p.sync_id_last = 140;
  p.save_r_first = 90;
  p.workpiece_k0_param = 99;
  p.drift_alive_param = d.param_first;
  p.workpiece_slope_param = 97;
  p.md32760 = kMd32760Max;
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({20.0, 40.0}, 4.0, 1.0);
  const double feed = 2.0, thread = 300.0;
  const CompensationPlan plan = BuildPlan(curve, feed, thread, p);

  replay::Replay r;
  r.control.abs_value_mm = 0.0007;
  r.control.slope = 3e-6;
  r.control.ref_position_mm = 12.0;
  r.axis_mm = AxisPositionMm(p, feed, 0.0) + 1.0;  // before the thread start, travelling -Z
  // An offset-only drift action does not own the slope: the plan refuses to start (mode alarm).
  SetInputs(r, d, Temperatures(0));
  DriftActionOptions offset_only = d;
  offset_only.workpiece_slope_param = -1;
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, offset_only)));
  EXPECT_FALSE(r.RunProgram(FormatNcProgram(plan)));
  EXPECT_EQ(r.control.alarm, p.drift_missing_alarm + 2);

  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, d, "", &g)));
  ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan)));
  drift::DriftEvaluator ev_k(m, m.reference_C), ev_g(g, g.reference_C);
  const double t_end = thread / feed;
  const double sign = Sign(d);
  double worst_um = 0;
  for (int k = 0; k * kCycleMs / 1000.0 <= t_end + 2.0; ++k) {
    const double t_s = k * kCycleMs / 1000.0;
    const double pos = AxisPositionMm(p, feed, std::min(t_s, t_end)) - (t_s > t_end ? 1.0 : 0.0);
    SetInputs(r, d, Temperatures(k));
    r.Cycle(pos);
    const double e_k = ev_k.Step(t_s / 60.0, Temperatures(k));
    const double e_g = ev_g.Step(t_s / 60.0, Temperatures(k));
    const double machine_mm = sign / 1000.0 * (e_k - e_g * (pos - 5587.5) / 1000.0);
    if (t_s >= t_end) {  // the plan's part is back to 0: the machine line alone
      EXPECT_NEAR(r.control.DkMm(pos), machine_mm, 1e-8);
      continue;
    }
    const double workpiece_um = (r.control.DkMm(pos) - machine_mm) * 1000.0 / SignFactor(p.sign);
    worst_um = std::max(worst_um, std::abs(workpiece_um - curve.ElongationUm(t_s)));
  }
  EXPECT_LE(worst_um, p.tolerance_um + 1e-6);
  r.EndProgram();
  ASSERT_TRUE(r.RunProgram(FormatNcResetProgram(p)));  // nothing to restore for the plan
  ASSERT_TRUE(r.RunProgram(FormatDriftNcResetProgram(d)));
  EXPECT_EQ(r.control.abs_value_mm, 0.0007);
  EXPECT_EQ(r.control.slope, 3e-6);
  EXPECT_EQ(r.control.ref_position_mm, 12.0);
  EXPECT_TRUE(r.actions.empty());
}

// Combined with the drift action (K0 handed over, or K0, slope and reference): while the axis is
// parked before the thread start and on the approach, the control applies the machine part alone,
// exactly as before the plan's call; nothing of the plan's first segment (its slope about the
// thread start) is extrapolated to the parking position. Both directions of travel, near and far.
TEST(DriftAction, CombinedTheApproachKeepsWhatTheControlAppliedBeforeTheCall) {
  std::mt19937 rng(1814);
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({20.0, 40.0}, 4.0, 1.0);
  const double feed = 2.0, thread = 300.0;
  for (int direction : {1, -1})
    for (bool slope_handed_over : {false, true})
      for (double before_mm : {1.0, 2000.0}) {
        const drift::DriftModel m = HandModel(true, rng), g = SlopeModel();
        DriftActionOptions d = SlopeOptions(ControlDk::kAdded, direction, direction);
        d.workpiece_k0_param = 99;
        if (slope_handed_over) d.workpiece_slope_param = 97;
        PlanOptions p;
        p.direction = direction;
        p.sign = ExpectedSign(p.direction, p.control_dk);
        p.start_position_mm = direction > 0 ? 100.0 : 6200.0;
        p.machine_offset_mm = -812.5;
        p.sync_id_first = 100;
        p.sync_id_last = 140;
        p.save_r_first = 90;
        p.workpiece_k0_param = 99;
        p.workpiece_slope_param = d.workpiece_slope_param;
        p.drift_alive_param = d.param_first;
        p.md32760 = kMd32760Max;
        const CompensationPlan plan = BuildPlan(curve, feed, thread, p);
        const double start = plan.segments.front().sd43920_mm;
        const double park = start - direction * before_mm;
        replay::Replay r;
        r.control.abs_value_mm = 0.0007;  // found values
        r.control.slope = 3e-6;
        r.control.ref_position_mm = 12.0;
        r.axis_mm = park;
        SetInputs(r, d, Temperatures(0));  // constant temperatures: the machine part stays put
        ASSERT_TRUE(r.RunProgram(slope_handed_over ? FormatDriftNcProgram(m, d, "", &g)
                                                   : FormatDriftNcProgram(m, d)));
        for (int k = 0; k < 3; ++k) r.Cycle(park);
        const replay::Control before = r.control;  // what the control applies before the call
        double worst_call_mm = 0;
        r.between_blocks = [&] {
          worst_call_mm =
              std::max(worst_call_mm, std::abs(r.control.DkMm(park) - before.DkMm(park)));
        };
        ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan))) << "alarm " << r.control.alarm;
        r.between_blocks = nullptr;
        const double worst_approach_mm = r.WorstDeviationOnApproach(park, start, 200, before);
        SCOPED_TRACE("direction " + std::to_string(direction) + ", slope handed over " +
                     std::to_string(slope_handed_over) + ", parked " + std::to_string(before_mm) +
                     " mm before the start");
        EXPECT_EQ(worst_call_mm, 0.0);
        EXPECT_EQ(worst_approach_mm, 0.0);
        // At the thread start the plan's first segment joins the machine part (l(0) = 0 here):
        // handed over, the machine line goes on; with K0 only, the plan's slope replaces the
        // found one and the machine's K0 remains.
        r.Cycle(start);
        EXPECT_NEAR(r.control.DkMm(start),
                    slope_handed_over ? before.DkMm(start) : before.abs_value_mm,
                    std::abs(curve.ElongationUm(0.0)) / 1000.0 + 1e-9);
        ASSERT_FALSE(HasFailure());
      }
}

// The plans check the running action, not a retentive marker: after a power cycle (actions and
// $AC_PARAM gone, R parameters kept) a combined plan refuses to start; a plan that writes the
// setting data itself refuses while a drift action runs; a drift program refuses while a plan's
// own compensation is still on the control.
TEST(DriftAction, LivenessNotMarkersDecideWhoMayWrite) {
  std::mt19937 rng(1813);
  const drift::DriftModel m = HandModel(false, rng);
  DriftActionOptions d = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  d.workpiece_k0_param = 99;
  d.plan_marker_r = 93;
  PlanOptions p;
  p.sync_id_first = 100;
  p.sync_id_last = 140;
  p.save_r_first = 90;
  p.drift_alive_param = d.param_first;
  p.md32760 = kMd32760Max;
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({20.0, 40.0}, 4.0, 1.0);
  PlanOptions combined = p;
  combined.workpiece_k0_param = 99;
  const CompensationPlan plan = BuildPlan(curve, 2.0, 300.0, combined);
  const CompensationPlan standalone = BuildPlan(curve, 2.0, 300.0, p);

  replay::Replay r;
  const double park = -1.0;  // before the thread start at 0
  r.axis_mm = park;
  SetInputs(r, d, Temperatures(0));
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, d)));
  ASSERT_TRUE(r.RunProgram(FormatNcProgram(plan)));  // running: accepted
  r.EndProgram();
  // A plan that writes SD43900 itself beside the running action: refused, nothing written.
  const double k0 = r.control.abs_value_mm;
  EXPECT_FALSE(r.RunProgram(FormatNcProgram(standalone)));
  EXPECT_EQ(r.control.alarm, p.drift_missing_alarm + 1);
  r.Cycle(park);
  EXPECT_EQ(r.control.abs_value_mm, k0);
  // Power cycle: the markers R81 survive, the action does not: the combined plan refuses.
  r.PowerOn();
  EXPECT_EQ(r.control.r[d.save_r_first + 1], 1.0);
  r.control.alarm = 0;
  EXPECT_FALSE(r.RunProgram(FormatNcProgram(plan)));
  EXPECT_EQ(r.control.alarm, p.drift_missing_alarm);
  // A standalone plan aborted mid-cut leaves R93 = 1: the drift program refuses to start (it
  // would save the plan's values as the control's own).
  replay::Replay q;
  q.axis_mm = park;
  ASSERT_TRUE(q.RunProgram(FormatNcProgram(standalone)));
  q.EndProgram();
  EXPECT_FALSE(q.RunProgram(FormatDriftNcProgram(m, d)));
  EXPECT_EQ(q.control.alarm, d.missing_alarm + 3);
  EXPECT_TRUE(q.actions.empty());
  ASSERT_TRUE(q.RunProgram(FormatNcResetProgram(p)));
  EXPECT_TRUE(q.RunProgram(FormatDriftNcProgram(m, d)));
}

// A program without a slope gives back the slope an aborted slope run left behind.
TEST(DriftAction, OffsetOnlyProgramGivesBackAnAbandonedSlope) {
  std::mt19937 rng(1812);
  const drift::DriftModel m = HandModel(false, rng), g = SlopeModel();
  const DriftActionOptions o = SlopeOptions(ControlDk::kAdded, 1, 1);
  replay::Replay r;
  r.control.slope = 2e-6;
  r.control.ref_position_mm = -5.0;
  SetInputs(r, o, Temperatures(0));
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, o, "", &g)));
  r.Cycle(0.0);
  EXPECT_NE(r.control.slope, 2e-6);
  r.EndProgram();  // aborted: no reset program
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, o)));
  r.Cycle(0.0);
  EXPECT_EQ(r.control.slope, 2e-6);
  EXPECT_EQ(r.control.ref_position_mm, -5.0);
}

// A mixed line (DriftComponent: docs/machine-history.md "Fourteenth round: adoption"), by
// hand: two static models at u = (1, 1) K, e_A = 1 + 2 - 1 = 2 um and e_B = 4 + 0.5 + 0.5 = 5 um,
// weights 0.25 / 0.75: SD43900 = s (0.5 + 3.75) / 1000 = 0.00425 mm (s = +1: subtracted, +1).
TEST(DriftAction, MixedLineByHand) {
  const drift::DriftModel a = HandModel(false, {1.0, 2.0, -1.0});
  const drift::DriftModel b = HandModel(false, {4.0, 0.5, 0.5});
  const DriftActionOptions o = Options(ControlDk::kSubtracted, 1, DriftReference::kModel);
  replay::Replay r;
  SetInputs(r, o, Eigen::Vector2d(25.5, 27.25));  // the references 24.5, 26.25 plus 1 K
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram({{&a, nullptr, nullptr, 0.25},
                                                 {&b, nullptr, nullptr, 0.75}}, o)));
  r.Cycle(0.0);
  EXPECT_NEAR(r.control.abs_value_mm, 0.00425, 1e-12);
}

// Two components, each with its own lags and slope model (one of them without a slope), weights
// 0.3 / 0.7: the control applies s/1000 (sum_j w_j e_K,j + sigma (sum_j w_j e_g,j) (P - P_b) /
// 1000) at every position, every cycle, each e from the component's own DriftEvaluator. The
// header's counts are the program's: IDs, the last slot, every line within 512 characters.
TEST(DriftAction, MixedLineIsTheWeightedSumOfItsComponentsLines) {
  std::mt19937 rng(1841);
  for (bool second_slope : {true, false})
    for (auto control : {ControlDk::kAdded, ControlDk::kSubtracted}) {
      const drift::DriftModel m1 = HandModel(true, rng), g1 = SlopeModel();
      const drift::DriftModel m2 = HandModel(false, rng);
      const drift::DriftModel g2 = HandModel(true, {0.3, -2.0, 1.0, 0.5, 4.0, -1.5, 2.5});
      const double w = 0.3;
      const DriftActionOptions o = SlopeOptions(control, -1, -1);
      const std::vector<DriftComponent> parts = {
          {&m1, &g1, nullptr, w}, {&m2, second_slope ? &g2 : nullptr, nullptr, 1 - w}};
      const std::string nc = FormatDriftNcProgram(parts, o);
      replay::Replay r;
      SetInputs(r, o, Temperatures(0));
      ASSERT_TRUE(r.RunProgram(nc)) << nc;
      drift::DriftEvaluator k1(m1, m1.reference_C), s1(g1, g1.reference_C),
          k2(m2, m2.reference_C), s2(g2, g2.reference_C);
      double worst_mm = 0, second_mm = 0;
      for (int k = 0; k < 1200; ++k) {
        SetInputs(r, o, Temperatures(k));
        r.Cycle(0.0);
        const double t = k * kCycleMs / 60000.0;
        const Eigen::Vector2d u = Temperatures(k);
        const double e_k1 = k1.Step(t, u), e_g1 = s1.Step(t, u), e_k2 = k2.Step(t, u);
        const double e_g2 = second_slope ? s2.Step(t, u) : 0.0;
        for (double p : {-812.5, 2500.0, 5587.5, 6400.0}) {
          const double line = (w * e_k1 + (1 - w) * e_k2) -
                              (w * e_g1 + (1 - w) * e_g2) * (p - 5587.5) / 1000.0;  // sigma -1
          const double first = e_k1 - e_g1 * (p - 5587.5) / 1000.0;
          worst_mm = std::max(worst_mm, std::abs(r.control.DkMm(p) - Sign(o) * line / 1000.0));
          second_mm = std::max(second_mm, std::abs(line - first) / 1000.0);
        }
      }
      EXPECT_LT(worst_mm, 1e-8) << nc;
      EXPECT_GT(second_mm, 1e-4) << "the second component must move the line";
      // The counts the header and the requirements state are the program's own.
      int ids = 0, largest_slot = -1;
      std::istringstream lines(nc);
      for (std::string line; std::getline(lines, line);) {
        EXPECT_LE(line.size(), 512u) << line;
        ids += line.rfind("IDS=", 0) == 0;
        for (std::size_t at = line.find("$AC_PARAM["); at != std::string::npos;
             at = line.find("$AC_PARAM[", at + 1))
          if (line[0] != ';') largest_slot = std::max(largest_slot, std::stoi(line.substr(at + 10)));
      }
      double actions = -1, slots = -1;
      for (const ControlRequirement& q : DriftRequirements(parts, o)) {
        if (q.datum.rfind("MD28250", 0) == 0) actions = q.value;
        if (q.datum.rfind("MD28254", 0) == 0) slots = q.value;
      }
      EXPECT_EQ(actions, ids);
      EXPECT_EQ(slots, largest_slot + 1);
      EXPECT_NE(nc.find("room for " + std::to_string(ids) + " static actions"), std::string::npos);
      EXPECT_NE(nc.find("; component 2, w = 0.7000000000: model "), std::string::npos);
      ASSERT_FALSE(HasFailure());
    }
}

// One component of weight 1 is the single-model program, byte for byte (NC, PLC table,
// requirements); a mixed PLC table tags every row by component and weight.
TEST(DriftAction, OneComponentIsTheSingleModelProgram) {
  std::mt19937 rng(1842);
  const drift::DriftModel m = HandModel(true, rng), g = SlopeModel();
  const DriftActionOptions o = SlopeOptions(ControlDk::kAdded, 1, 1);
  EXPECT_EQ(FormatDriftNcProgram({{&m, &g, nullptr, 1.0}}, o, "src"),
            FormatDriftNcProgram(m, o, "src", &g));
  EXPECT_EQ(FormatDriftPlcCsv({{&m, &g, nullptr, 1.0}}, o), FormatDriftPlcCsv(m, o, &g));
  EXPECT_EQ(DriftSlopeBound({{&m, &g, nullptr, 1.0}}, o), DriftSlopeBound(g, o));
  const drift::DriftModel m2 = HandModel(false, rng);
  const std::string csv = FormatDriftPlcCsv({{&m, &g, nullptr, 0.6}, {&m2, nullptr, nullptr, 0.4}}, o);
  std::istringstream lines(csv);
  int rows1 = 0, rows2 = 0;
  bool header = false;
  for (std::string line; std::getline(lines, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      EXPECT_EQ(line.rfind("component,weight,output,feature,", 0), 0u) << line;
      header = true;
      continue;
    }
    rows1 += line.rfind("1,0.6000000000,", 0) == 0;
    rows2 += line.rfind("2,0.4000000000,k0_mm,", 0) == 0;
  }
  EXPECT_EQ(rows1, 7 + 3);  // component 1: intercept and 6 features, the slope's 1 and 2
  EXPECT_EQ(rows2, 3);      // component 2: intercept and 2 features, no slope
  EXPECT_NEAR(DriftSlopeBound({{&m, &g, nullptr, 0.6}, {&m2, nullptr, nullptr, 0.4}}, o),
              0.6 * DriftSlopeBound(g, o), 1e-15);
}

TEST(DriftAction, MixedLinesThatCannotBeRunAreRefused) {
  std::mt19937 rng(1843);
  const drift::DriftModel m = HandModel(true, rng), g = SlopeModel();
  const DriftActionOptions o = SlopeOptions(ControlDk::kAdded, 1, 1);
  const BlankTerm blank{"t2_C", 1.0, -11.8, 15, 30};
  using Parts = std::vector<DriftComponent>;
  EXPECT_THROW(FormatDriftNcProgram(Parts{}, o), InputError);
  EXPECT_THROW(FormatDriftNcProgram(Parts{{&m, &g, nullptr, 0.5}, {&m, &g, nullptr, 0.4}}, o),
               InputError);  // weights sum to 0.9
  EXPECT_THROW(FormatDriftNcProgram(Parts{{&m, &g, nullptr, 1.0}, {&m, &g, nullptr, 0.0}}, o),
               InputError);  // weight 0
  EXPECT_THROW(FormatDriftNcProgram(Parts{{nullptr, &g, nullptr, 0.5}, {&m, &g, nullptr, 0.5}}, o),
               InputError);  // no offset model
  EXPECT_THROW(FormatDriftNcProgram(Parts{{&m, &g, &blank, 0.5}, {&m, &g, &blank, 0.5}}, o),
               InputError);  // two blank terms, one blank_param
  EXPECT_THROW(FormatDriftPlcCsv(Parts{{&m, &g, nullptr, 0.5}, {&m, &g, nullptr, 0.4}}, o),
               InputError);
  EXPECT_NO_THROW(FormatDriftNcProgram(Parts{{&m, &g, nullptr, 0.5}, {&m, &g, nullptr, 0.5}}, o));
}

TEST(DriftAction, RefusesWhatTheControlCannotRun) {
  std::mt19937 rng(1806);
  drift::DriftModel m = HandModel(true, rng);
  DriftActionOptions o = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  o.inputs.erase("t2_C");
  EXPECT_THROW(FormatDriftNcProgram(m, o), InputError);  // unmapped sensor
  o = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  o.sync_id_last = o.sync_id_first + 2;
  EXPECT_THROW(FormatDriftNcProgram(m, o), InputError);  // too few IDs
  o = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  o.workpiece_k0_param = o.param_first + 1;
  EXPECT_THROW(FormatDriftNcProgram(m, o), InputError);  // slot collision
  m.time_unit = "sample";
  EXPECT_THROW(FormatDriftNcProgram(m, Options(ControlDk::kAdded, 1, DriftReference::kModel)),
               InputError);  // lags in samples
  // Slope models: without the profile's slope object; with a plan that keeps SD43910 itself;
  // the plan's slope slots inside the action's own.
  const drift::DriftModel g = SlopeModel();
  m = HandModel(false, rng);
  o = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  EXPECT_THROW(FormatDriftNcProgram(m, o, "", &g), InputError);
  o = SlopeOptions(ControlDk::kAdded, 1, 1);
  o.workpiece_k0_param = 99;
  EXPECT_THROW(FormatDriftNcProgram(m, o, "", &g), InputError);
  o.workpiece_slope_param = o.param_first + 3;
  EXPECT_THROW(FormatDriftNcProgram(m, o, "", &g), InputError);
  o.workpiece_slope_param = 98;  // its second slot is workpiece_k0_param
  EXPECT_THROW(FormatDriftNcProgram(m, o, "", &g), InputError);
  o.workpiece_slope_param = 97;
  EXPECT_NO_THROW(FormatDriftNcProgram(m, o, "", &g));
  m.kind = drift::ModelKind::kNetwork;
  EXPECT_THROW(FormatDriftNcProgram(m, Options(ControlDk::kAdded, 1, DriftReference::kModel)),
               InputError);
}

// Physical bounds of the mapping and the control's own limits (MD10300 analog inputs, MD28254
// $AC_PARAM, the profile's param_last): refused with the datum named; the header names the
// program by its name and states what the program needs from the control.
TEST(DriftAction, ControlLimitsAndBoundsAreCheckedAndNamed) {
  std::mt19937 rng(1815);
  const drift::DriftModel m = HandModel(true, rng);
  const DriftActionOptions good = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  auto refused = [&](const std::function<void(DriftActionOptions&)>& edit,
                     const std::string& word) {
    DriftActionOptions o = good;
    edit(o);
    try {
      FormatDriftNcProgram(m, o);
      ADD_FAILURE() << "accepted; expected a message with '" << word << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  refused([](DriftActionOptions& o) { o.inputs["t1_C"].scale = 1e-12; }, "scale");
  refused([](DriftActionOptions& o) { o.inputs["t1_C"].scale = -2e3; }, "scale");
  refused([](DriftActionOptions& o) { o.inputs["t1_C"].offset = 1e308; }, "offset");
  refused([](DriftActionOptions& o) { o.inputs["t1_C"].offset = NAN; }, "offset");
  refused([](DriftActionOptions& o) { o.inputs["t1_C"].index = 1000; }, "index");
  refused([](DriftActionOptions& o) { o.ipo_cycle_ms = 1e-9; }, "ipo_cycle_ms");
  refused([](DriftActionOptions& o) { o.missing_alarm = 60000; }, "missing_alarm");
  refused(
      [](DriftActionOptions& o) {
        o.control = {8, 400, 300};
        o.inputs["t2_C"].index = 9;
      },
      "MD10300");
  refused([](DriftActionOptions& o) { o.control = {8, 400, 105}; }, "MD28254");
  refused([](DriftActionOptions& o) { o.param_last = 105; }, "param_last");  // needs 100..109
  refused([](DriftActionOptions& o) { o.program_name = "1 my comp"; }, "program name");
  refused([](DriftActionOptions& o) { o.reset_program_name = "whirl_drift_comp"; }, "one program");
  DriftActionOptions o = good;
  o.control = {8, 400, 300};
  o.param_last = 109;  // exactly what the model needs
  o.program_name = "MACHINE_DRIFT";
  o.reset_program_name = "MACHINE_DRIFT_OFF";
  const std::string nc = FormatDriftNcProgram(m, o);
  EXPECT_EQ(nc.rfind("; MACHINE_DRIFT: ", 0), 0u);
  EXPECT_NE(nc.find("stop it with MACHINE_DRIFT_OFF"), std::string::npos);
  EXPECT_NE(nc.find("MD10300 $MN_FASTIO_ANA_NUM_INPUTS >= 7 (profile: 8)"), std::string::npos);
  EXPECT_NE(nc.find("MD28254 $MC_MM_NUM_AC_PARAM >= 110 (profile: 300)"), std::string::npos);
  EXPECT_NE(nc.find("MD28250 $MC_MM_NUM_SYNC_ELEMENTS"), std::string::npos);
  EXPECT_EQ(nc.find("WHIRL_DRIFT"), std::string::npos);
  EXPECT_EQ(FormatDriftNcResetProgram(o).rfind("; MACHINE_DRIFT_OFF: ", 0), 0u);
}

TEST(DriftAction, HostileNamesStayInsideCommentsAndCells) {
  std::mt19937 rng(1808);
  drift::DriftModel m = HandModel(true, rng);
  m.error_column = "ch1_um\nM30\r\n$$SA_TEMP_COMP_SLOPE[Z]=1,x";
  const DriftActionOptions o = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  replay::Replay r;
  ASSERT_TRUE(r.RunProgram(FormatDriftNcProgram(m, o, "model\nM30\n.json")));  // no unknown line
  EXPECT_EQ(r.control.slope, 0.0);
  std::istringstream csv(FormatDriftPlcCsv(m, o));
  std::string line;
  while (std::getline(csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 9) << line;
  }
  // A mixed line names its file in the header's first line too (ModelLines' mix branch).
  const drift::DriftModel b = HandModel(false, rng);
  const std::vector<DriftComponent> parts = {{&m, nullptr, nullptr, 0.5},
                                             {&b, nullptr, nullptr, 0.5}};
  replay::Replay mixed;
  ASSERT_TRUE(mixed.RunProgram(FormatDriftNcProgram(parts, o, "mix\nM30\n.json")));
  EXPECT_EQ(mixed.control.slope, 0.0);
  std::istringstream mixed_csv(FormatDriftPlcCsv(parts, o));
  while (std::getline(mixed_csv, line)) {
    if (line.empty() || line[0] == '#') continue;
    EXPECT_EQ(std::count(line.begin(), line.end(), ','), 11) << line;  // + component, weight
  }
}

// Sensor names holding '"', ',', a line break or a formula start: every data row of the PLC table
// read by RFC 4180 has the header's 10 cells, and the input cell gives the name back (after the
// spreadsheet guard's apostrophe), so a '"' never sits inside an unquoted cell.
TEST(DriftAction, PlcTableCellsFollowRfc4180) {
  const std::vector<std::string> names = {"t\"1\" C", "=t2,C\r\nx"};
  drift::DriftModel m = HandModel(false, {1.0, 2.0, -3.0});
  m.sensors = names;
  for (std::size_t i = 0; i < names.size(); ++i) m.features[i].input = names[i];
  m.Validate();
  DriftActionOptions o = Options(ControlDk::kAdded, 1, DriftReference::kModel);
  o.inputs = {{names[0], {3, 0.1, -20.0}}, {names[1], {7, 0.05, 0.0}}};
  std::string table;
  std::istringstream text(FormatDriftPlcCsv(m, o));
  for (std::string line; std::getline(text, line);)
    if (line.empty() || line[0] != '#') table += line + "\n";
  const auto records = test::ParseRfc4180(table);
  ASSERT_EQ(records.size(), 4u) << table;  // header, the intercept, one row per sensor
  std::vector<std::string> inputs;
  for (const auto& r : records) {
    ASSERT_EQ(r.size(), 10u) << table;
    inputs.push_back(r[2]);
  }
  EXPECT_EQ(inputs[2], names[0]);
  EXPECT_EQ(inputs[3], "'" + names[1]);
}

TEST(DriftAction, GoldenProgramAndPlcTable) {
  // Fixed coefficients (the file pins the text, so no value may depend on a standard library's
  // random distributions): intercept, then t1_C direct and lagged, t2_C likewise.
  const drift::DriftModel m = HandModel(true, {1.25, 3.5, -0.75, 0.4, -2.2, 0.9, 1.6});
  DriftActionOptions o = Options(ControlDk::kAdded, 1, DriftReference::kStart);
  o.workpiece_k0_param = 99;
  o.plan_marker_r = 93;  // the start check for a plan left active, and its jump to the end
  const std::string nc = FormatDriftNcProgram(m, o, "golden model") + FormatDriftNcResetProgram(o) +
                         FormatDriftPlcCsv(m, o);
  const std::string path = std::string(WHIRL_SOURCE_DIR) + "/tests/interp/golden/drift_action.spf";
  if (std::getenv("WHIRL_UPDATE_GOLDEN") != nullptr) WriteFileAtomic(path, nc);
  EXPECT_EQ(nc, ReadTextFile(path)) << "actual:\n" << nc;
  // With the machine's slope, handed over by the plan.
  const drift::DriftModel g = SlopeModel();
  DriftActionOptions os = SlopeOptions(ControlDk::kAdded, -1, -1);
  os.workpiece_k0_param = 99;
  os.workpiece_slope_param = 97;
  const std::string nc_slope =
      FormatDriftNcProgram(m, os, "golden model", &g) + FormatDriftPlcCsv(m, os, &g);
  const std::string path_slope =
      std::string(WHIRL_SOURCE_DIR) + "/tests/interp/golden/drift_action_slope.spf";
  if (std::getenv("WHIRL_UPDATE_GOLDEN") != nullptr) WriteFileAtomic(path_slope, nc_slope);
  EXPECT_EQ(nc_slope, ReadTextFile(path_slope)) << "actual:\n" << nc_slope;
  // Sensors with two elapsed-time warm-up terms (drift fit's candidates with time).
  const drift::DriftModel e = ElapsedModel({"t1_C", "t2_C"}, {35.5, 240.0}, {0.6, 1.5, -0.8, 3.25, 1.75});
  const DriftActionOptions oe = Options(ControlDk::kAdded, 1, DriftReference::kStart);
  const std::string nc_elapsed = FormatDriftNcProgram(e, oe, "golden model") +
                                 FormatDriftNcResetProgram(oe) + FormatDriftPlcCsv(e, oe);
  const std::string path_elapsed =
      std::string(WHIRL_SOURCE_DIR) + "/tests/interp/golden/drift_action_elapsed.spf";
  if (std::getenv("WHIRL_UPDATE_GOLDEN") != nullptr) WriteFileAtomic(path_elapsed, nc_elapsed);
  EXPECT_EQ(nc_elapsed, ReadTextFile(path_elapsed)) << "actual:\n" << nc_elapsed;
}

}  // namespace
}  // namespace whirl::interp
