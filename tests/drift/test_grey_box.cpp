// The grey-box estimator of drift/grey_box.h on planted worlds whose truth is known: recovery of
// every coefficient (offset, slope on absolute temperatures, slope intercept, the blank latched
// at the cut start), the evaluator against the closed-form lag of a step, priors kept where no
// reading sees a column, collinear sensors that cannot trade opposite coefficients, bad options.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/random.h"
#include "drift/grey_box.h"
#include "drift/grey_box_io.h"
#include "drift/measurement_file.h"
#include "support/expect_error.h"
#include "support/scratch_dir.h"

namespace whirl::drift {
namespace grey_box_test {

// A day log: a head sensor warming from the day's level, a screw sensor and the hall's air at
// their own absolute levels (different per day: absolute temperature matters for the slope).
Run DayLog(int day, int minutes, bool twin = false) {
  Run r;
  r.name = "day" + std::to_string(day);
  r.sensor_names = {"head", "screw", "air"};
  if (twin) r.sensor_names.push_back("screw_twin");
  r.temperature_C.resize(minutes + 1, static_cast<Eigen::Index>(r.sensor_names.size()));
  Rng rng(100 + static_cast<std::uint64_t>(day));
  const double level = 17.0 + 1.7 * day - 0.45 * day * day;
  for (int k = 0; k <= minutes; ++k) {
    const double t = k;
    r.time_min.push_back(t);
    r.temperature_C(k, 0) = level + (3 + 0.5 * day) * (1 - std::exp(-t / (30.0 + 10 * day)));
    r.temperature_C(k, 1) = level + 0.6 + 0.004 * t * (1 + day % 2) + 0.3 * std::sin(t / 50.0);
    r.temperature_C(k, 2) = level - 0.3 + std::sin(t / (60.0 + 9 * day) + day);
    if (twin) r.temperature_C(k, 3) = r.temperature_C(k, 1) + 0.02 * rng.Normal();
  }
  return r;
}

GreyBoxModel Truth() {
  GreyBoxModel t;
  t.offset_sensors = {"head"};
  t.slope_sensors = {"screw"};
  t.blank_sensor = "air";
  t.time_constants = {40};
  t.z_ref_mm = 6400;
  t.a.resize(2);
  t.a << 1.5, -2.5;
  t.g.resize(2);
  t.g << 7.0, 4.5;
  t.slope_intercept_um_per_1000 = 3.0;
  t.blank_tau_min = 60;
  t.blank_um_per_1000_per_k = -11.8;
  return t;
}

// Per day: a probe series at z = 150 mm, laser targets at 1000 and 4000 mm (one record each), and
// two lead records (cuts from z = 5000 mm towards the chuck at 20 mm/min, starting at minutes
// 60 and 200). Each record has an unknown zero; values = the truth, no noise.
// With duty: the log also carries the control's signals (other columns, as logged): a load in
// percent that steps with the cuts and a Z speed in mm/min during them.
Run DutyDayLog(int day, int minutes) {
  Run r = DayLog(day, minutes);
  r.other_names = {"load_pct", "speed_mm_min"};
  r.other.resize(minutes + 1, 2);
  for (int k = 0; k <= minutes; ++k) {
    const bool cut = (k >= 60 && k <= 180) || (k >= 200 && k <= 320);
    r.other(k, 0) = cut ? 20.0 + 15.0 * ((day + k / 60) % 3) : 2.0;
    r.other(k, 1) = cut ? 20.0 + 5.0 * (day % 2) : 0.0;
  }
  return r;
}

// Measurement noise of sd `sd_um` on every planted reading (its own generator, `seed`).
void AddNoise(ShopRecord* rec, double sd_um, std::uint64_t seed) {
  Rng rng(seed);
  for (auto& r : rec->records)
    for (auto& x : r.rows) x.value_um += sd_um * rng.Normal();
}

ShopRecord Planted(const GreyBoxModel& truth, bool leads, int days = 5,
                   const std::function<Run(int, int)>& day_log = [](int d, int m) {
                     return DayLog(d, m);
                   }) {
  ShopRecord rec;
  Rng rng(7);
  for (int day = 0; day < days; ++day) {
    rec.day_logs.push_back(day_log(day, 360));
    auto add = [&](MeasurementRecord r) {
      const std::vector<double> m = PredictGreyRecord(truth, rec, r);
      const double zero = 5.0 * rng.Normal();
      for (std::size_t i = 0; i < r.rows.size(); ++i) r.rows[i].value_um = m[i] + zero;
      rec.records.push_back(std::move(r));
    };
    for (double z : {150.0, 1000.0, 4000.0}) {
      MeasurementRecord r;
      r.kind = z == 150 ? MeasurementRecord::Kind::kProbe : MeasurementRecord::Kind::kLaser;
      r.day = day;
      r.log = day;
      for (int k = 0; k <= 360; k += 10) r.rows.push_back({k, double(k), z, 0, 1.0});
      add(r);
    }
    if (!leads) continue;
    for (int start : {60, 200}) {
      MeasurementRecord r;
      r.kind = MeasurementRecord::Kind::kLead;
      r.day = day;
      r.log = day;
      for (int k = 0; k <= 120; k += 5)
        r.rows.push_back({start + k, double(start + k), 5000.0 - 20.0 * k, 0, 2.0});
      add(r);
    }
  }
  return rec;
}

// The truth with a duty input on each channel: the load heats the head, the speed the screw.
GreyBoxModel DutyTruth() {
  GreyBoxModel t = Truth();
  t.offset_duty = {"load_pct"};
  t.slope_duty = {"speed_mm_min"};
  t.a.resize(4);
  t.a << 1.5, -2.5, 0.08, 0.05;
  t.g.resize(4);
  t.g << 7.0, 4.5, -0.02, 0.06;
  return t;
}

GreyBoxSpec SpecOf(const GreyBoxModel& t) {
  GreyBoxSpec s;
  s.offset_sensors = t.offset_sensors;
  s.slope_sensors = t.slope_sensors;
  s.offset_duty = t.offset_duty;
  s.slope_duty = t.slope_duty;
  s.blank_sensor = t.blank_sensor;
  s.z_ref_mm = t.z_ref_mm;
  return s;
}

GreyBoxOptions Fixed(const GreyBoxModel& t, double strength) {
  GreyBoxOptions o;
  o.tau_grid = t.time_constants;
  o.max_lags = 1;
  o.blank_tau_grid = {t.blank_tau_min};
  o.strength_grid = {strength};
  return o;
}

TEST(GreyBox, RecoversEveryPlantedCoefficientIncludingTheLatchedBlank) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, true);
  const GreyBoxModel m = FitGreyBox(rec, SpecOf(t), Fixed(t, 1e-10));
  ASSERT_EQ(m.time_constants, t.time_constants);
  for (Eigen::Index j = 0; j < 2; ++j) {
    EXPECT_NEAR(m.a(j), t.a(j), 1e-3) << j;
    EXPECT_NEAR(m.g(j), t.g(j), 1e-3) << j;
  }
  EXPECT_NEAR(m.slope_intercept_um_per_1000, t.slope_intercept_um_per_1000, 1e-3);
  EXPECT_NEAR(m.blank_um_per_1000_per_k, t.blank_um_per_1000_per_k, 1e-3);
  EXPECT_LT(m.cv_rmse_um, 1e-3);
}

// Duty inputs (the control's signals as logged, with the same lags) are recovered beside the
// temperatures, and a fit without them cannot explain the same readings.
TEST(GreyBox, RecoversPlantedDutyInputsOnBothChannels) {
  const GreyBoxModel t = DutyTruth();
  const ShopRecord rec = Planted(t, true, 5, DutyDayLog);
  const GreyBoxModel m = FitGreyBox(rec, SpecOf(t), Fixed(t, 1e-10));
  ASSERT_EQ(m.a.size(), 4);
  ASSERT_EQ(m.g.size(), 4);
  EXPECT_EQ(m.offset_duty, t.offset_duty);
  EXPECT_EQ(m.slope_duty, t.slope_duty);
  for (Eigen::Index j = 0; j < 4; ++j) {
    EXPECT_NEAR(m.a(j), t.a(j), 1e-3) << j;
    EXPECT_NEAR(m.g(j), t.g(j), 1e-3) << j;
  }
  EXPECT_NEAR(m.blank_um_per_1000_per_k, t.blank_um_per_1000_per_k, 1e-3);
  EXPECT_LT(m.cv_rmse_um, 1e-3);
  for (const MeasurementRecord& r : rec.records) {
    const std::vector<double> p = PredictGreyRecord(m, rec, r), q = PredictGreyRecord(t, rec, r);
    for (std::size_t i = 0; i < p.size(); ++i) EXPECT_NEAR(p[i], q[i], 1e-3);
  }
  const GreyBoxModel without = FitGreyBox(rec, SpecOf(Truth()), Fixed(t, 1e-10));
  EXPECT_GT(without.cv_rmse_um, 0.1);
  // A duty input the logs lack is named.
  GreyBoxSpec s = SpecOf(t);
  s.slope_duty = {"no_such_signal"};
  ExpectInputError([&] { FitGreyBox(rec, s, Fixed(t, 1e-2)); }, "no_such_signal");
}

TEST(GreyBox, TheSearchFindsThePlantedLagsAmongOthers) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, true);
  GreyBoxOptions o;
  o.tau_grid = {10, 40, 160};
  o.max_lags = 1;
  o.blank_tau_grid = {15, 240, 60};  // the search starts from the middle one
  o.strength_grid = {1e-10, 1e-1};
  // The share this planted design was made for (the default is 0.9 since issue 41's eighth
  // round; with 0.9 this greedy search, which picks the lags before the blank's lag, settles on
  // 160 min here).
  o.lead_share = 0.5;
  const GreyBoxModel m = FitGreyBox(rec, SpecOf(t), o);
  EXPECT_EQ(m.time_constants, std::vector<double>{40});
  EXPECT_DOUBLE_EQ(m.blank_tau_min, 60);
  EXPECT_DOUBLE_EQ(m.prior_strength, 1e-10);
}

// Without a lead record no reading sees the blank or the slope intercept: both keep their priors
// exactly, whatever the strength.
TEST(GreyBox, AColumnNoReadingSeesKeepsItsPrior) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, false);
  GreyBoxSpec s = SpecOf(t);
  s.blank_prior = -9.25;
  for (double strength : {1e-6, 1.0}) {
    const GreyBoxModel m = FitGreyBox(rec, s, Fixed(t, strength));
    EXPECT_NEAR(m.blank_um_per_1000_per_k, -9.25, 1e-9);
    EXPECT_NEAR(m.slope_intercept_um_per_1000, 0.0, 1e-9);
  }
}

// A strong prior pulls towards the physical coefficients: with strength -> large the fitted
// slope coefficients approach the prior (spread equally over the static and lagged columns).
TEST(GreyBox, AStrongPriorHoldsThePhysicalCoefficients) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, true);
  GreyBoxSpec s = SpecOf(t);
  s.slope_prior = {{"screw", 11.5}};
  GreyBoxOptions o = Fixed(t, 1e6);
  o.lead_share = 0.5;  // with 0.9 the search keeps no lag here (the prior then stays whole on
                       // the reading's column); the spread over the lag is what is checked
  const GreyBoxModel m = FitGreyBox(rec, s, o);
  ASSERT_EQ(m.time_constants, t.time_constants);
  EXPECT_NEAR(m.g(0), 5.75, 1e-3);
  EXPECT_NEAR(m.g(1), 5.75, 1e-3);
  EXPECT_NEAR(m.blank_um_per_1000_per_k, s.blank_prior, 1e-3);
}

// Two sensors 0.02 K apart (noise) read the same screw: an unregularized fit trades large
// opposite coefficients on them; the grey box's ridge towards the prior keeps both moderate and
// their sum at the truth.
TEST(GreyBox, CollinearSensorsCannotTradeOppositeCoefficients) {
  const GreyBoxModel t = Truth();
  ShopRecord rec = Planted(t, true);
  for (int d = 0; d < static_cast<int>(rec.day_logs.size()); ++d) {
    const drift::Run twin = DayLog(d, 360, true);
    rec.day_logs[static_cast<std::size_t>(d)] = twin;
  }
  AddNoise(&rec, 0.3, 3);
  GreyBoxSpec s = SpecOf(t);
  s.slope_sensors = {"screw", "screw_twin"};
  const GreyBoxModel m = FitGreyBox(rec, s, Fixed(t, 1e-2));
  const double sum = m.g.sum();
  EXPECT_NEAR(sum, t.g.sum(), 0.15 * t.g.sum());
  EXPECT_LT(m.g.cwiseAbs().maxCoeff(), t.g.sum());
}

// The evaluator's blank estimate is the exact first-order lag of a held step, and K0 / slope are
// the closed forms of the static inputs.
TEST(GreyBox, TheEvaluatorFollowsTheClosedFormLagOfAStep) {
  GreyBoxModel m = Truth();
  m.time_constants.clear();
  m.a.resize(1);
  m.a << 2.0;
  m.g.resize(1);
  m.g << 3.0;
  GreyBoxEvaluator ev(m);
  Eigen::VectorXd raw(3);
  raw << 22.0, 21.0, 18.0;
  ev.Step(0, raw);
  raw << 23.0, 25.0, 24.0;
  for (double t = 10; t <= 300; t += 10) {
    const GreyBoxEvaluator::Output o = ev.Step(t, raw);
    EXPECT_NEAR(o.blank_c, 24.0 - 6.0 * std::exp(-(t - 0) / m.blank_tau_min), 1e-12) << t;
    EXPECT_NEAR(o.k0_um, 2.0 * 3.0, 1e-12);
    EXPECT_NEAR(o.slope_um_per_1000, 3.0 + 3.0 * 5.0, 1e-12);
    EXPECT_NEAR(ev.BlankSlope(o.blank_c), -11.8 * (o.blank_c - 20), 1e-12);
  }
}

// Forward chaining on the leads (GreyValidation::kForwardLeads), against a reference built from
// the public API alone: for each of the last forward_days days, the grey box fitted on the
// records of the earlier days (the same fixed choice), its prediction of that day's leads, each
// lead compared up to its own zero (a record is known up to a constant), pooled RMS. Every
// planted day holds the same records, so the lead share's scaling is the same on every prefix.
TEST(GreyBox, ForwardValidationScoresTheLeadsOfEachDayFromTheDaysBefore) {
  const GreyBoxModel t = Truth();
  ShopRecord rec = Planted(t, true, 6);
  AddNoise(&rec, 0.5, 11);
  GreyBoxOptions o = Fixed(t, 1e-2);
  o.validation = GreyValidation::kForwardLeads;
  o.forward_days = 3;
  const GreyBoxModel m = FitGreyBox(rec, SpecOf(t), o);
  double num = 0;
  int count = 0;
  for (int day = 3; day < 6; ++day) {
    ShopRecord before;
    before.day_logs = rec.day_logs;
    for (const auto& r : rec.records)
      if (r.day < day) before.records.push_back(r);
    const GreyBoxModel fit = FitGreyBox(before, SpecOf(t), Fixed(t, 1e-2));
    for (const auto& r : rec.records) {
      if (r.day != day || r.kind != MeasurementRecord::Kind::kLead) continue;
      const std::vector<double> p = PredictGreyRecord(fit, rec, r);
      Eigen::VectorXd res(static_cast<Eigen::Index>(p.size()));
      for (std::size_t i = 0; i < p.size(); ++i)
        res(static_cast<Eigen::Index>(i)) = r.rows[i].value_um - p[i];
      res.array() -= res.mean();
      num += res.squaredNorm();
      count += static_cast<int>(p.size());
    }
  }
  EXPECT_NEAR(m.cv_rmse_um, std::sqrt(num / count), 1e-9);
  // Leave one day out scores every record: another figure on the same fit.
  EXPECT_GT(std::abs(FitGreyBox(rec, SpecOf(t), Fixed(t, 1e-2)).cv_rmse_um - m.cv_rmse_um),
            1e-3);
}

// With fewer than 2 x forward_days days holding a lead (none, or a short history) forward
// chaining does not score and the fit is the leave-one-day-out fit exactly; from 2 x forward_days
// lead days on it does.
TEST(GreyBox, ForwardValidationNeedsTwiceItsDaysOfLeadsElseItIsLeaveOneDayOut) {
  const GreyBoxModel t = Truth();
  ShopRecord leads = Planted(t, true, 6);
  AddNoise(&leads, 0.5, 5);
  for (const auto& [rec, days] : {std::pair{Planted(t, false, 4), 2}, std::pair{leads, 4}}) {
    GreyBoxOptions o;
    o.tau_grid = {10, 40, 160};
    o.max_lags = 1;
    o.forward_days = days;
    const GreyBoxModel lodo = FitGreyBox(rec, SpecOf(t), o);
    o.validation = GreyValidation::kForwardLeads;
    const GreyBoxModel forward = FitGreyBox(rec, SpecOf(t), o);
    EXPECT_EQ(forward.time_constants, lodo.time_constants);
    EXPECT_EQ(forward.prior_strength, lodo.prior_strength);
    EXPECT_EQ(forward.cv_rmse_um, lodo.cv_rmse_um);
    EXPECT_EQ(forward.a, lodo.a);
  }
  GreyBoxOptions o;
  o.forward_days = 3;  // 6 lead days: forward chaining scores, another figure
  const double lodo = FitGreyBox(leads, SpecOf(t), o).cv_rmse_um;
  o.validation = GreyValidation::kForwardLeads;
  EXPECT_GT(std::abs(FitGreyBox(leads, SpecOf(t), o).cv_rmse_um - lodo), 1e-3);
}

// Forward chaining scores the planted lags and the planted blank lag best (the leads alone
// identify them; a weak prior, since each validation fit has only the days before it). Each is
// searched with the other fixed: the greedy search's path (lags first, from the middle blank lag)
// is the same under either score and is not what this checks.
TEST(GreyBox, ForwardValidationFindsThePlantedLagsAndTheBlanksLag) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, true, 6);
  GreyBoxOptions o;
  o.max_lags = 1;
  o.strength_grid = {1e-10};
  o.validation = GreyValidation::kForwardLeads;
  o.forward_days = 3;
  o.tau_grid = {10, 40, 160};
  o.blank_tau_grid = {60};
  GreyBoxModel m = FitGreyBox(rec, SpecOf(t), o);
  EXPECT_EQ(m.time_constants, std::vector<double>{40});
  EXPECT_LT(m.cv_rmse_um, 1e-3);
  o.tau_grid = {40};
  o.blank_tau_grid = {15, 240, 60};
  m = FitGreyBox(rec, SpecOf(t), o);
  EXPECT_DOUBLE_EQ(m.blank_tau_min, 60);
  EXPECT_LT(m.cv_rmse_um, 1e-3);
}

// A world whose bodies follow their sensors only through a lag (instant coefficients 0): with
// the temperatures through their lags only (instant_offset_inputs / instant_slope_inputs false)
// the fit recovers every planted lag coefficient, keeps each instant coefficient at 0 exactly,
// and predicts every reading as the truth does; a sensor's noise on its instant reading then
// cannot reach the compensation at once.
GreyBoxModel LaggedTruth() {
  GreyBoxModel t = Truth();
  t.a << 0.0, -4.0;
  t.g << 0.0, 11.5;
  return t;
}

TEST(GreyBox, LagsOnlyRecoversALaggedWorldWithInstantCoefficientsExactlyZero) {
  const GreyBoxModel t = LaggedTruth();
  const ShopRecord rec = Planted(t, true);
  GreyBoxOptions o = Fixed(t, 1e-10);
  o.instant_offset_inputs = o.instant_slope_inputs = false;
  const GreyBoxModel m = FitGreyBox(rec, SpecOf(t), o);
  ASSERT_EQ(m.time_constants, t.time_constants);
  EXPECT_EQ(m.a(0), 0.0);
  EXPECT_EQ(m.g(0), 0.0);
  EXPECT_NEAR(m.a(1), -4.0, 1e-3);
  EXPECT_NEAR(m.g(1), 11.5, 1e-3);
  EXPECT_NEAR(m.slope_intercept_um_per_1000, t.slope_intercept_um_per_1000, 1e-3);
  EXPECT_NEAR(m.blank_um_per_1000_per_k, t.blank_um_per_1000_per_k, 1e-3);
  EXPECT_LT(m.cv_rmse_um, 1e-3);
  for (const MeasurementRecord& r : rec.records) {
    const std::vector<double> p = PredictGreyRecord(m, rec, r), q = PredictGreyRecord(t, rec, r);
    for (std::size_t i = 0; i < p.size(); ++i) EXPECT_NEAR(p[i], q[i], 1e-3);
  }
  // The planted world of the other tests moves the instant columns: lags alone cannot fit it.
  const ShopRecord instant = Planted(Truth(), true);
  EXPECT_GT(FitGreyBox(instant, SpecOf(t), o).cv_rmse_um, 0.1);
}

// Without the instant column an input's prior goes to its lags alone (here one lag: the whole
// prior), on the channel switched off only; with no lag to hold it the instant column stays and
// the fit is the default fit exactly. (The lagged world makes the lag the better choice of the
// search even when a strong prior holds every coefficient.)
TEST(GreyBox, LagsOnlyPutsThePriorOnTheLagsAndNeedsALag) {
  const GreyBoxModel t = LaggedTruth();
  const ShopRecord rec = Planted(t, true);
  GreyBoxSpec s = SpecOf(t);
  s.offset_prior = {{"head", -4.0}};
  s.slope_prior = {{"screw", 11.5}};
  GreyBoxOptions o = Fixed(t, 1e6);
  o.instant_slope_inputs = false;
  const GreyBoxModel m = FitGreyBox(rec, s, o);
  ASSERT_EQ(m.time_constants, t.time_constants);
  EXPECT_NEAR(m.a(0), -2.0, 1e-3);  // offset: instant and lag share the prior, as by default
  EXPECT_NEAR(m.a(1), -2.0, 1e-3);
  EXPECT_EQ(m.g(0), 0.0);
  EXPECT_NEAR(m.g(1), 11.5, 1e-3);
  GreyBoxOptions none = Fixed(t, 1e-2);
  none.max_lags = 0;
  const GreyBoxModel plain = FitGreyBox(rec, s, none);
  none.instant_offset_inputs = none.instant_slope_inputs = false;
  const GreyBoxModel lagless = FitGreyBox(rec, s, none);
  ASSERT_TRUE(lagless.time_constants.empty());
  EXPECT_EQ(lagless.a, plain.a);
  EXPECT_EQ(lagless.g, plain.g);
  EXPECT_NE(lagless.a(0), 0.0);
}

// short_record_offset_lags (issue 41's thirteenth round): on a record with fewer than
// 2 x forward_days lead days the offset sensors keep their instant column and the first `lags`
// of the chosen lags. The planted truth needs its 40-min lag (the slope and the offset both
// follow lags), so the lag is chosen either way; with the offset as read its lag coefficient is
// exactly 0 (the evaluator and the 840D programs run the model as it is), the slope keeps its
// lag and the offset's missing lag shows in the validation error. Keeping one lag of one chosen
// changes nothing; from 2 x forward_days lead days (forward_days 2: 5 lead days of 4 needed)
// the option changes nothing, bit for bit.
TEST(GreyBox, ShortRecordOffsetLagsDropTheOffsetLagsOnlyOnAShortRecord) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, true);
  ASSERT_EQ(LeadDays(rec).size(), 5u);
  GreyBoxOptions o = Fixed(t, 1e-10);
  EXPECT_EQ(o.short_record_offset_lags, -1);  // off by default
  const GreyBoxModel plain = FitGreyBox(rec, SpecOf(t), o);
  ASSERT_EQ(plain.time_constants, t.time_constants);
  GreyBoxOptions read = o, one = o;
  read.short_record_offset_lags = 0;
  one.short_record_offset_lags = 1;
  const GreyBoxModel m = FitGreyBox(rec, SpecOf(t), read);
  ASSERT_EQ(m.time_constants, t.time_constants);
  EXPECT_EQ(m.a(1), 0.0);
  EXPECT_NE(m.a(0), 0.0);
  EXPECT_NE(m.g(1), 0.0);
  EXPECT_GT(m.cv_rmse_um, plain.cv_rmse_um + 1e-3);
  EXPECT_EQ(nlohmann::json(FitGreyBox(rec, SpecOf(t), one)), nlohmann::json(plain));
  for (GreyBoxOptions* x : {&o, &read}) x->forward_days = 2;
  ASSERT_TRUE(LongRecord(rec, read));
  EXPECT_EQ(nlohmann::json(FitGreyBox(rec, SpecOf(t), read)),
            nlohmann::json(FitGreyBox(rec, SpecOf(t), o)));
}

// Where the prior rules (strength 1e9) each coefficient is its prior, spread equally over an
// input's columns: with the offset as read the whole prior of the offset sensor (6 um/K) sits on
// its instant column, its lag's coefficient 0; with the lag it is 3 and 3. The slope's prior is
// spread over both of its columns in both fits. (The planted truth is the priors spread over
// both columns, so the lag is chosen at this strength too.)
TEST(GreyBox, TheOffsetAsReadCarriesItsWholePriorOnTheInstantColumn) {
  GreyBoxModel t = Truth();
  t.a << 3.0, 3.0;
  t.g << 5.75, 5.75;
  const ShopRecord rec = Planted(t, true);
  GreyBoxSpec spec = SpecOf(t);
  spec.offset_prior = {{"head", 6.0}};
  spec.slope_prior = {{"screw", 11.5}};
  GreyBoxOptions o = Fixed(t, 1e9);
  const GreyBoxModel every = FitGreyBox(rec, spec, o);
  o.short_record_offset_lags = 0;
  const GreyBoxModel read = FitGreyBox(rec, spec, o);
  for (const GreyBoxModel* m : {&every, &read}) {
    ASSERT_EQ(m->time_constants, t.time_constants) << "no lag chosen: the test could not fail";
    EXPECT_NEAR(m->g(0), 5.75, 1e-5);
    EXPECT_NEAR(m->g(1), 5.75, 1e-5);
  }
  EXPECT_NEAR(every.a(0), 3.0, 1e-5);
  EXPECT_NEAR(every.a(1), 3.0, 1e-5);
  EXPECT_NEAR(read.a(0), 6.0, 1e-5);
  EXPECT_EQ(read.a(1), 0.0);
}

TEST(GreyBox, BadOptionsAndMissingColumnsAreNamed) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, false, 2);
  GreyBoxOptions o = Fixed(t, 1e-2);
  o.lead_share = 1.0;
  EXPECT_THROW(
      {
        try {
          FitGreyBox(rec, SpecOf(t), o);
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find("lead_share"), std::string::npos);
          throw;
        }
      },
      InputError);
  o = Fixed(t, 1e-2);
  o.forward_days = 1;
  ExpectInputError([&] { FitGreyBox(rec, SpecOf(t), o); }, "forward_days = 1: must be within");
  o = Fixed(t, 1e-2);
  o.blank_tau_grid = {0};
  EXPECT_THROW(FitGreyBox(rec, SpecOf(t), o), InputError);
  for (double bad : {0.0, -1.0, std::nan("")}) {
    o = Fixed(t, 1e-2);
    o.short_record_strength_grid = {bad};
    ExpectInputError([&] { FitGreyBox(rec, SpecOf(t), o); }, "short_record_strength_grid holds");
  }
  for (int bad : {-2, 5}) {
    o = Fixed(t, 1e-2);
    o.short_record_offset_lags = bad;
    ExpectInputError([&] { FitGreyBox(rec, SpecOf(t), o); },
                     "short_record_offset_lags = " + std::to_string(bad) + ": must be -1");
  }
  GreyBoxSpec s = SpecOf(t);
  s.slope_sensors = {"no_such_sensor"};
  EXPECT_THROW(FitGreyBox(rec, s, Fixed(t, 1e-2)), InputError);
  s = SpecOf(t);
  s.offset_sensors.clear();
  s.slope_sensors.clear();
  EXPECT_THROW(FitGreyBox(rec, s, Fixed(t, 1e-2)), InputError);
}

// The files (drift/grey_box_io.h, drift/measurement_file.h): sensors named as run files name
// them (<name>_C).
ShopRecord Renamed(ShopRecord rec) {
  for (Run& log : rec.day_logs)
    for (std::string& n : log.sensor_names) n += "_C";
  return rec;
}

GreyBoxSpec RenamedSpec(const GreyBoxModel& t) {
  GreyBoxSpec s = SpecOf(t);
  for (auto* list : {&s.offset_sensors, &s.slope_sensors})
    for (std::string& n : *list) n += "_C";
  s.blank_sensor += "_C";
  return s;
}

void ExpectSameModel(const GreyBoxModel& a, const GreyBoxModel& b, double tol) {
  EXPECT_EQ(a.offset_sensors, b.offset_sensors);
  EXPECT_EQ(a.slope_sensors, b.slope_sensors);
  EXPECT_EQ(a.blank_sensor, b.blank_sensor);
  EXPECT_EQ(a.offset_duty, b.offset_duty);
  EXPECT_EQ(a.slope_duty, b.slope_duty);
  EXPECT_EQ(a.time_constants, b.time_constants);
  EXPECT_EQ(a.z_ref_mm, b.z_ref_mm);
  ASSERT_EQ(a.a.size(), b.a.size());
  ASSERT_EQ(a.g.size(), b.g.size());
  EXPECT_LE((a.a - b.a).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((a.g - b.g).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((a.offset_min - b.offset_min).cwiseAbs().maxCoeff(), tol);
  EXPECT_LE((a.slope_max - b.slope_max).cwiseAbs().maxCoeff(), tol);
  EXPECT_NEAR(a.slope_intercept_um_per_1000, b.slope_intercept_um_per_1000, tol);
  EXPECT_NEAR(a.blank_um_per_1000_per_k, b.blank_um_per_1000_per_k, tol);
  EXPECT_EQ(a.blank_tau_min, b.blank_tau_min);
  EXPECT_NEAR(a.blank_min_c, b.blank_min_c, tol);
  EXPECT_NEAR(a.blank_max_c, b.blank_max_c, tol);
  EXPECT_NEAR(a.cv_rmse_um, b.cv_rmse_um, tol);
  EXPECT_EQ(a.rows, b.rows);
}

TEST(GreyBoxFiles, TheModelFileRoundTripsExactlyAndPredictsTheSame) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Planted(t, true);
  GreyBoxModel m = FitGreyBox(rec, SpecOf(t), Fixed(t, 1e-2));
  m.notes = {"fitted by a test"};
  const auto path = test::ScratchDir() / "grey.json";
  WriteGreyBoxModel(path, m);
  const GreyBoxModel back = ReadGreyBoxModel(path);
  ExpectSameModel(m, back, 0.0);
  EXPECT_EQ(back.notes, m.notes);
  for (const MeasurementRecord& r : rec.records)
    EXPECT_EQ(PredictGreyRecord(back, rec, r), PredictGreyRecord(m, rec, r));
  // The ranges are those of the evaluator on the logs: B stays within them.
  EXPECT_LT(m.blank_min_c, m.blank_max_c);
  EXPECT_GE((m.offset_max - m.offset_min).minCoeff(), 0.0);
}

TEST(GreyBoxFiles, AModelWithDutyInputsRoundTripsExactly) {
  const GreyBoxModel t = DutyTruth();
  const ShopRecord rec = Planted(t, true, 5, DutyDayLog);
  const GreyBoxModel m = FitGreyBox(rec, SpecOf(t), Fixed(t, 1e-2));
  const auto path = test::ScratchDir() / "grey_duty.json";
  WriteGreyBoxModel(path, m);
  const GreyBoxModel back = ReadGreyBoxModel(path);
  ExpectSameModel(m, back, 0.0);
  for (const MeasurementRecord& r : rec.records)
    EXPECT_EQ(PredictGreyRecord(back, rec, r), PredictGreyRecord(m, rec, r));
  // The duty feature's range is that of the signal as logged (2..50 %), not against 20 degC.
  EXPECT_DOUBLE_EQ(m.offset_min(2), 2.0);
  EXPECT_DOUBLE_EQ(m.offset_max(2), 50.0);
  // A file whose duty feature names the wrong input is refused with the rule.
  nlohmann::json j = ReadJsonFile(path);
  j["offset_features"][2]["input"] = "head_C";
  const auto bad = test::ScratchDir() / "grey_duty_bad.json";
  WriteJsonFile(bad, j);
  ExpectInputError([&] { ReadGreyBoxModel(bad); }, "then each duty input");
}

TEST(GreyBoxFiles, FittedFromTheRecordsFileItIsTheModelOfTheRecordsInMemory) {
  const GreyBoxModel t = Truth();
  const ShopRecord rec = Renamed(Planted(t, true, 3));
  const auto dir = test::ScratchDir() / "records";
  std::filesystem::create_directories(dir / "logs");
  std::vector<std::string> paths;
  for (std::size_t i = 0; i < rec.day_logs.size(); ++i) {
    paths.push_back("logs/day" + std::to_string(i) + ".csv");
    WriteFileAtomic(dir / paths.back(), FormatRun(rec.day_logs[i], {"planted day log"}));
  }
  WriteFileAtomic(dir / "records.json", FormatMeasurementRecords(rec, paths, "planted"));
  const MeasurementFile f = ReadMeasurementRecords(dir / "records.json");
  ASSERT_EQ(f.record.records.size(), rec.records.size());
  for (std::size_t i = 0; i < rec.records.size(); ++i)
    for (std::size_t k = 0; k < rec.records[i].rows.size(); ++k)
      EXPECT_EQ(f.record.records[i].rows[k].sample, rec.records[i].rows[k].sample);
  const GreyBoxOptions o = Fixed(t, 1e-2);
  ExpectSameModel(FitGreyBox(f.record, RenamedSpec(t), o), FitGreyBox(rec, RenamedSpec(t), o),
                  1e-6);
}

// A file with one field changed from a valid one: the error names the field and the rule.
void ExpectBadModel(const std::function<void(nlohmann::json&)>& change, const std::string& what) {
  GreyBoxModel m = FitGreyBox(Planted(Truth(), true, 2), SpecOf(Truth()), Fixed(Truth(), 1e-2));
  nlohmann::json j = m;
  change(j);
  const auto path = test::ScratchDir() / "bad_grey.json";
  WriteFileAtomic(path, j.dump());
  ExpectInputError([&] { (void)ReadGreyBoxModel(path); }, what);
}

// Values no machine can hold (a fixed bearing behind the chuck face, temperatures a run file
// refuses, below absolute zero): each is refused with the file, the field, the value and the rule;
// the same file with every such value at its limit reads back and writes back unchanged.
TEST(GreyBoxFiles, PhysicallyImpossibleValuesAreRefusedAndTheLimitsRoundTrip) {
  const GreyBoxModel fitted =
      FitGreyBox(Planted(Truth(), true, 2), SpecOf(Truth()), Fixed(Truth(), 1e-2));
  const nlohmann::json valid = fitted;
  const auto path = test::ScratchDir() / "impossible_grey.json";
  struct Case {
    std::vector<std::string> where;  // JSON path
    double value;
    std::vector<std::string> fragments;  // of the message, each
  };
  const std::vector<Case> hostile = {
      {{"z_ref_mm"},
       -100001,
       {"z_ref_mm = -100001 breaks the rule: must lie in [-100000, 100000] mm"}},
      {{"offset_features", "0", "train_min_k"}, -293.15,
       {"offset_features[0].train_min_k = -293.15 breaks the rule: must lie in [-80, 380] K"}},
      {{"slope_features", "1", "train_max_k"}, 380.5,
       {"slope_features[1].train_max_k = 380.5 breaks the rule: must lie in [",
        "380] K (at least train_min_k)"}},
      {{"blank", "train_min_c"}, -61,
       {"blank.train_min_c = -61 breaks the rule: must lie in [-60, 400] degC"}},
      {{"blank", "train_max_c"}, 1000,
       {"blank.train_max_c = 1000 breaks the rule", "400] degC (at least train_min_c)"}}};
  auto at = [](nlohmann::json& j, const std::vector<std::string>& where) -> nlohmann::json& {
    nlohmann::json* x = &j;
    for (const std::string& k : where)
      x = x->is_array() ? &(*x)[std::stoul(k)] : &(*x)[k];
    return *x;
  };
  for (const Case& c : hostile) {
    nlohmann::json j = valid;
    at(j, c.where) = c.value;
    WriteFileAtomic(path, j.dump());
    const std::string error = whirl::ErrorOf([&] { (void)ReadGreyBoxModel(path); });
    EXPECT_NE(error.find(path.string()), std::string::npos) << error;
    for (const std::string& f : c.fragments) EXPECT_NE(error.find(f), std::string::npos) << error;
  }
  // Every such value at its limit: read, written and read again, the same file.
  nlohmann::json limits = valid;
  limits["z_ref_mm"] = -100000.0;  // a fixed bearing behind the chuck face is negative
  limits["offset_features"][0]["train_min_k"] = -80.0;
  limits["slope_features"][1]["train_max_k"] = 380.0;
  limits["blank"]["train_min_c"] = -60.0;
  limits["blank"]["train_max_c"] = 400.0;
  WriteFileAtomic(path, limits.dump());
  const GreyBoxModel read = ReadGreyBoxModel(path);
  EXPECT_EQ(read.z_ref_mm, -100000.0);
  EXPECT_EQ(read.offset_min(0), -80.0);
  EXPECT_EQ(read.blank_max_c, 400.0);
  const auto again = test::ScratchDir() / "impossible_grey_again.json";
  WriteGreyBoxModel(again, read);
  EXPECT_EQ(nlohmann::json(ReadGreyBoxModel(again)), limits);
  // The spec the model is fitted to: the same rule for its z_ref_mm, naming the file.
  const auto spec = test::ScratchDir() / "impossible_spec.json";
  WriteFileAtomic(spec, R"({"format": "whirl-grey-box-spec", "schema_version": 1,
    "offset_sensors": ["a_C"], "slope_sensors": ["b_C"], "blank_sensor": "", "z_ref_mm": 2e5,
    "blank_prior_um_per_1000_per_k": -11.8})");
  const std::string error = whirl::ErrorOf([&] { (void)ReadGreyBoxSpec(spec); });
  EXPECT_NE(error.find(spec.string()), std::string::npos) << error;
  EXPECT_NE(error.find("z_ref_mm = 200000 breaks the rule: must lie in [-100000, 100000] mm"),
            std::string::npos)
      << error;
}

TEST(GreyBoxFiles, BadModelSpecAndRecordsFilesNameFileFieldAndRule) {
  ExpectBadModel([](nlohmann::json& j) { j["offset_features"][0]["coefficient"] = 1e9; },
                 "offset_features[0].coefficient = 1e+09 breaks the rule");
  ExpectBadModel([](nlohmann::json& j) { j["slope_features"].erase(0); }, "'slope_features' has");
  ExpectBadModel([](nlohmann::json& j) { j["blank"] = nullptr; }, "'blank' must be null exactly");
  ExpectBadModel([](nlohmann::json& j) { j["time_constants_min"] = {-5}; }, "time_constants_min");
  ExpectBadModel([](nlohmann::json& j) { j["z_ref_mm"] = 1e9; }, "z_ref_mm");
  ExpectBadModel([](nlohmann::json& j) { j["format"] = "whirl-drift-model"; }, "not a grey box");
  ExpectBadModel([](nlohmann::json& j) { j["blank"]["train_max_c"] = -900; }, "train_max_c");
  ExpectBadModel([](nlohmann::json& j) { j["extra"] = 1; }, "extra");
  // The path is named.
  ExpectBadModel([](nlohmann::json& j) { j["fit"]["cv_rmse_um"] = -1; }, "bad_grey.json");
  // A grey box handed to a command that takes a drift model (drift predict, drift nc --model):
  // the error says what the file is and which option takes it.
  const auto grey = test::ScratchDir() / "grey_as_drift.json";
  WriteFileAtomic(grey, nlohmann::json(FitGreyBox(Planted(Truth(), true, 2), SpecOf(Truth()),
                                                  Fixed(Truth(), 1e-2)))
                            .dump());
  ExpectInputError([&] { (void)ReadDriftModel(grey); }, "drift nc --grey-model");
  // Spec: a prior for a sensor not in its list would be ignored silently.
  const auto spec = test::ScratchDir() / "spec.json";
  const std::string good = R"({"format": "whirl-grey-box-spec", "schema_version": 1,
    "offset_sensors": ["a_C"], "slope_sensors": ["b_C"], "blank_sensor": "c_C", "z_ref_mm": 6400,
    "offset_prior_um_per_k": {"a_C": 1.5}, "blank_prior_um_per_1000_per_k": -11.8})";
  WriteFileAtomic(spec, good);
  EXPECT_EQ(ReadGreyBoxSpec(spec).offset_prior.at("a_C"), 1.5);
  std::string bad = good;
  bad.replace(bad.find("{\"a_C\": 1.5}"), 12, "{\"b_C\": 1.5}");
  WriteFileAtomic(spec, bad);
  ExpectInputError([&] { (void)ReadGreyBoxSpec(spec); }, "'offset_prior_um_per_k' names 'b_C'");
  bad = good;
  bad.replace(bad.find("[\"b_C\"]"), 7, "[\"a_C\", \"a_C\"]");
  WriteFileAtomic(spec, bad);
  ExpectInputError([&] { (void)ReadGreyBoxSpec(spec); }, "names 'a_C' twice");
  // Records: a reading outside its log, a sigma of 0, arrays of different lengths, a log index
  // out of range; each names the record and the field.
  const ShopRecord rec = Renamed(Planted(Truth(), false, 1));
  const auto dir = test::ScratchDir() / "bad_records";
  std::filesystem::create_directories(dir);
  WriteFileAtomic(dir / "day0.csv", FormatRun(rec.day_logs[0]));
  const nlohmann::json valid =
      nlohmann::json::parse(FormatMeasurementRecords(rec, {"day0.csv"}, ""));
  auto expect_bad = [&](const std::function<void(nlohmann::json&)>& change,
                        const std::string& what) {
    nlohmann::json j = valid;
    change(j);
    WriteFileAtomic(dir / "records.json", j.dump());
    ExpectInputError([&] { (void)ReadMeasurementRecords(dir / "records.json"); }, what);
  };
  expect_bad([](nlohmann::json& j) { j["records"][1]["time_min"][2] = 999.0; },
             "'records'[1] reading 2: time_min 999 lies outside its day log");
  expect_bad([](nlohmann::json& j) { j["records"][0]["sigma_um"][0] = 0.0; },
             "'records'[0] reading 0: sigma_um = 0 breaks the rule");
  expect_bad([](nlohmann::json& j) { j["records"][0]["z_mm"].erase(0); }, "one value per reading");
  expect_bad([](nlohmann::json& j) { j["records"][0]["log"] = 3; }, "'records'[0]: 'log'");
  expect_bad([](nlohmann::json& j) { j["records"][0]["kind"] = "gauge"; }, "kind");
  expect_bad([](nlohmann::json& j) { j["day_logs"] = {"missing.csv"}; }, "missing.csv");
}

}  // namespace grey_box_test
}  // namespace whirl::drift
