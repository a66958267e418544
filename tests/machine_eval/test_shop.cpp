// Training from shop measurements and causal application (machine_eval/shop_models.h,
// machine_eval/strategies.h), and the seeds summary. That no truth reaches a trained model is
// tested on the field world (test_field_eval.cpp, FieldTraining).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>

#include "core/error.h"
#include "core/random.h"
#include "core/json_file.h"
#include "drift/grey_box_io.h"
#include "drift/grey_mix.h"
#include "support/expect_error.h"
#include "support/scratch_dir.h"
#include "machine_eval/machine_eval.h"
#include "machine_eval/shop_models.h"
#include "machine_eval/strategies.h"
#include "machine_eval/summary.h"

namespace whirl::machine_eval {
namespace {

// A model by hand: one sensor and power_on, one lag of 20 min, offset and slope coefficients.
drift::JointDriftModel HandModel() {
  drift::JointDriftModel m;
  m.sensors = {"s1_C"};
  m.other_inputs = {"power_on"};
  m.time_constants = {20};
  m.a.resize(4);
  m.a << 3.0, 2.0, 1.0, 4.0;
  m.g.resize(4);
  m.g << 0.5, -1.0, 0.0, 2.0;
  return m;
}

drift::Run HandLog(int samples, std::uint64_t seed) {
  drift::Run r;
  r.sensor_names = {"s1_C"};
  r.other_names = {"power_on"};
  r.temperature_C.resize(samples, 1);
  r.other.resize(samples, 1);
  Rng rng(seed);
  for (int k = 0; k < samples; ++k) {
    r.time_min.push_back(0.5 * k);
    r.temperature_C(k, 0) = 20 + 0.05 * k + 0.1 * rng.Normal();
    r.other(k, 0) = k == 0 ? 0 : 1;
  }
  return r;
}

// A planted shop record whose drift follows the time since power-on alone, while four sensors
// wander independently of it (they carry nothing): per day a log of 300 min (the control's duty
// columns power_on, ring_on, cutting and ring_load_pct), probe readings at z = 150 mm every 10 min, and on the
// first two days laser targets at 500, 3000 and 5500 mm; m = 20 w + 3 w (6400 - z) / 1000,
// w = 1 - exp(-t / 40), 1 um noise, a zero per record.
drift::ShopRecord SensorsCarryNothing(std::uint64_t seed, int days) {
  Rng rng(seed);
  drift::ShopRecord rec;
  for (int d = 0; d < days; ++d) {
    drift::Run log;
    log.name = "day" + std::to_string(d);
    log.sensor_names = {"s1", "s2", "s3", "s4"};
    log.other_names = {"power_on", "ring_on", "cutting", "ring_load_pct"};
    log.temperature_C.resize(301, 4);
    log.other.resize(301, 4);
    Eigen::RowVector4d walk(20, 21, 22, 23);
    const bool cutting = d % 2 == 1;
    for (int k = 0; k <= 300; ++k) {
      log.time_min.push_back(k);
      for (int j = 0; j < 4; ++j) walk(j) += 0.05 * rng.Normal();
      log.temperature_C.row(k) = walk;
      const double on = k == 0 ? 0.0 : 1.0;
      log.other.row(k) << on, on, cutting ? on : 0.0, on * (cutting ? 70.0 : 20.0);
    }
    rec.day_logs.push_back(log);
    std::vector<double> zs = {150};
    if (d < 2) zs = {150, 500, 3000, 5500};
    for (double z : zs) {
      drift::MeasurementRecord r;
      r.kind = z == 150 ? drift::MeasurementRecord::Kind::kProbe
                        : drift::MeasurementRecord::Kind::kLaser;
      r.day = d;
      r.log = d;
      const double zero = 50 * rng.Normal();
      for (int k = 0; k <= 300; k += 10) {
        const double w = 1 - std::exp(-k / 40.0);
        const double m = 20 * w + 3 * w * (6400 - z) / 1000;
        r.rows.push_back({k, double(k), z, m + zero + rng.Normal(), 1.0});
      }
      rec.records.push_back(r);
    }
  }
  return rec;
}

// Where the sensors carry nothing, the shop-trained sensor model is not worse than the warm-up
// rule in the grouped cross-validation (it can fall back to the sensor-free rules), and on a new
// day it predicts the drift within 1.5 x the warm-up rule's error + 0.5 um; over 6 random worlds.
TEST(ShopTraining, WhereSensorsCarryNothingTheSensorModelIsNotWorseThanWarmup) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const drift::ShopRecord rec = SensorsCarryNothing(seed, 6);
    const ShopModels m = FitShopModels(rec, 6400, {"ring_on", "cutting", "ring_load_pct"});
    EXPECT_LE(m.sensors.cv_rmse_um, m.warmup.cv_rmse_um + 1e-9) << "seed " << seed;
    // A new day of the same world: the error of each model's prediction at z = 1000 mm.
    const drift::ShopRecord test = SensorsCarryNothing(100 + seed, 1);
    drift::ShopRecord one = test;
    one.records = {test.records[1]};  // the laser target at 500 mm
    auto rms = [&](const drift::JointDriftModel& model) {
      const std::vector<double> p = drift::PredictRecord(model, one, one.records[0]);
      // readings carry a zero: compare the rises from the first reading
      double s = 0;
      for (std::size_t i = 0; i < p.size(); ++i) {
        const double w = 1 - std::exp(-one.records[0].rows[i].time_min / 40.0);
        const double truth = 20 * w + 3 * w * (6400 - 500) / 1000;
        const double e = (p[i] - p[0]) - truth;
        s += e * e;
      }
      return std::sqrt(s / static_cast<double>(p.size()));
    };
    EXPECT_LE(rms(m.sensors), 1.5 * rms(m.warmup) + 0.5)
        << "seed " << seed << " choice " << m.sensors_choice;
  }
}

// No look-ahead: replacing every control sample after i (sensors +5 K, duty doubled) leaves the
// applied compensation before sample i + 1 exactly unchanged, for random i and times.
TEST(CausalApplication, TheValueBeforeSampleIPlusOneIgnoresLaterSamples) {
  const drift::JointDriftModel m = HandModel();
  const drift::Run log = HandLog(200, 3);
  auto z = [](double t_s) { return 5000 - 0.6 * t_s; };
  const compare::CompensationFunction c = CausalMachineLine(RunCausally(m, log), 4.0, 6400, z);
  Rng rng(17);
  for (int trial = 0; trial < 50; ++trial) {
    const int i = 8 + static_cast<int>(rng.Uniform() * 180);
    drift::Run changed = log;
    for (int k = i + 1; k < changed.samples(); ++k) {
      changed.temperature_C(k, 0) += 5;
      changed.other(k, 0) *= 2;
    }
    const compare::CompensationFunction d =
        CausalMachineLine(RunCausally(m, changed), 4.0, 6400, z);
    const double t_next_s = (log.time_min[static_cast<std::size_t>(i) + 1] - 4.0) * 60.0;
    for (int q = 0; q < 20; ++q) {
      const double t = rng.Uniform() * t_next_s * (1 - 1e-12);
      ASSERT_EQ(c(t), d(t)) << "i " << i << " t " << t;
    }
    EXPECT_NE(c(t_next_s), d(t_next_s)) << "the change shows from sample i + 1 on";
  }
}

// The seventh round's rows (WithOffsetOf): with warmup's share 1 the held offset is warmup's
// exactly while the slope and the blank term stay the grey box's; share 0.5 gives the midpoint.
// On the line, hand-computed: at z = z_ref only K0 acts; 60 mm from it the grey box's slope and
// its blank term latched at the cut start. Models stepped through different logs are refused.
TEST(CausalApplication, WithOffsetOfTakesTheOffsetAndKeepsTheSlope) {
  const HeldSamples grey{{0, 1, 2}, {5, 6, 7}, {10, 11, 12}, {0.5, 0.6, 0.7}};
  const HeldSamples warm{{0, 1, 2}, {-1, 2.5, 3}, {99, 98, 97}, {}};
  const HeldSamples h = WithOffsetOf(grey, warm, 1.0);
  EXPECT_EQ(h.k0_um, warm.k0_um);
  EXPECT_EQ(h.slope_um_per_1000, grey.slope_um_per_1000);
  EXPECT_EQ(h.blank_slope_um_per_1000, grey.blank_slope_um_per_1000);
  EXPECT_EQ(WithOffsetOf(grey, warm, 0.5).k0_um, (std::vector<double>{2, 4.25, 5}));
  // Cut start at 0.5 min (sample 0: blank term 0.5 latched), z(t) = 6400 - 1 mm/s x t.
  const compare::CompensationFunction c =
      CausalMachineLine(h, 0.5, 6400, [](double t_s) { return 6400 - t_s; });
  EXPECT_DOUBLE_EQ(c(0), -1.0);                         // warmup's K0 of sample 0
  EXPECT_DOUBLE_EQ(c(60), 2.5 + (11 + 0.5) * 60 / 1000.0);  // sample 1: 3.19 um
  HeldSamples other = warm;
  other.time_min[2] = 3;
  EXPECT_THROW(WithOffsetOf(grey, other, 1.0), InputError);
}

// The fourteenth round's rows (MixedLines): the line w x grey's + (1 - w) x the rule's, every part
// of it (K0, slope, the blank term, which the rule lacks: 0), so each model's K0 and slope stay
// together; w 1 is the grey box's samples exactly (the rows are both_grey's from 20 lead days).
// On the line, hand-computed with w = 0.75: sample 0's K0 0.75 x 5 + 0.25 x (-1) = 3.5; at 60 s
// sample 1: K0 0.75 x 6 + 0.25 x 2.5 = 5.125, slope 0.75 x 11 + 0.25 x 98 = 32.75, the blank
// term latched at the cut start 0.75 x 0.5 = 0.375. Other logs and weights outside [0, 1] are
// refused.
TEST(CausalApplication, MixedLinesMixesEachModelsWholeLine) {
  const HeldSamples grey{{0, 1, 2}, {5, 6, 7}, {10, 11, 12}, {0.5, 0.6, 0.7}};
  const HeldSamples warm{{0, 1, 2}, {-1, 2.5, 3}, {99, 98, 97}, {}};
  const HeldSamples same = MixedLines(grey, warm, 1.0);
  EXPECT_EQ(same.k0_um, grey.k0_um);
  EXPECT_EQ(same.slope_um_per_1000, grey.slope_um_per_1000);
  EXPECT_EQ(same.blank_slope_um_per_1000, grey.blank_slope_um_per_1000);
  const HeldSamples h = MixedLines(grey, warm, 0.5);
  EXPECT_EQ(h.k0_um, (std::vector<double>{2, 4.25, 5}));
  EXPECT_EQ(h.slope_um_per_1000, (std::vector<double>{54.5, 54.5, 54.5}));
  EXPECT_EQ(h.blank_slope_um_per_1000, (std::vector<double>{0.25, 0.3, 0.35}));
  const HeldSamples rule_only = MixedLines(grey, warm, 0.0);
  EXPECT_EQ(rule_only.k0_um, warm.k0_um);
  EXPECT_EQ(rule_only.slope_um_per_1000, warm.slope_um_per_1000);
  EXPECT_EQ(rule_only.blank_slope_um_per_1000, (std::vector<double>{0, 0, 0}));
  const compare::CompensationFunction c = CausalMachineLine(
      MixedLines(grey, warm, 0.75), 0.5, 6400, [](double t_s) { return 6400 - t_s; });
  EXPECT_DOUBLE_EQ(c(0), 3.5);
  EXPECT_DOUBLE_EQ(c(60), 5.125 + (32.75 + 0.375) * 60 / 1000.0);
  HeldSamples other = warm;
  other.time_min[2] = 3;
  EXPECT_THROW(MixedLines(grey, other, 0.5), InputError);
  EXPECT_THROW(MixedLines(grey, warm, 1.5), InputError);
  EXPECT_THROW(MixedLines(grey, warm, -0.1), InputError);
}

// The headline names the sensor-free row with the smallest pooled thread median (none excluded,
// sensor rows never), and the per-seed medians bound the pooled one.
TEST(SeedsSummary, StrongestSensorFreeIsTheSmallestThreadMedianWithoutSensors) {
  std::array<SeedStats, kMachineStrategyCount> s{};
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) s[k].total_median_um = 50.0 - k;
  s[static_cast<std::size_t>(MachineStrategy::kNone)].total_median_um = 0.1;
  // 42: lead_slope, the last sensor-free row (the smaller values are sensor rows)
  EXPECT_EQ(StrongestSensorFree(s), MachineStrategy::kLeadSlope);
  s[static_cast<std::size_t>(MachineStrategy::kTable)].total_median_um = 5;
  EXPECT_EQ(StrongestSensorFree(s), MachineStrategy::kTable);
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    if (UsesSensors(static_cast<MachineStrategy>(k))) s[k].total_median_um = 0.01;
  EXPECT_EQ(StrongestSensorFree(s), MachineStrategy::kTable);
}

// The eighth round's opt-in grey boxes (shop_models.h FieldGreyCandidate) in a planted world:
// the field sensors' paths plus one sensor the field grey box does not read (z_motor_C), each day
// at its own levels; m planted as a grey box (drift/grey_box.h PredictGreyRecord) whose offset
// and slope follow the field sensors with the field spec's priors and whose slope also follows
// z_motor_C by 25 um per 1000 mm per K; probe readings at z = 150 mm and two leads a day.
drift::Run FieldLikeLog(int day) {
  drift::Run r;
  r.name = "day" + std::to_string(day);
  r.sensor_names = {"head_bearing_C", "head_housing_C", "bed_middle_C",
                    "ambient_C",      "z_nut_C",        "z_motor_C"};
  r.temperature_C.resize(361, 6);
  r.other_names = {"power_on"};  // minutes since the day's first row, as the control logs it
  r.other.resize(361, 1);
  const double level = 19.0 + 0.8 * std::sin(1.3 * day);
  for (int k = 0; k <= 360; ++k) {
    const double t = k;
    r.time_min.push_back(t);
    r.other(k, 0) = t;
    r.temperature_C.row(k) << level + 4 * (1 - std::exp(-t / 30)),
        level + 2 * (1 - std::exp(-t / 90)), level + 0.3 * (1 - std::exp(-t / 200)),
        level - 0.2 + 0.5 * std::sin(t / 70 + day), level + 0.002 * t + 0.2 * std::sin(t / 40),
        20.5 + 1.5 * std::sin(t / 55 + 2.1 * day) + 0.4 * (day % 3);
  }
  return r;
}

drift::GreyBoxModel MotorTruth(double motor_um_per_1000_per_k = 25) {
  const drift::GreyBoxSpec f = FieldGreyBoxSpec(6400);
  drift::GreyBoxModel t;
  t.offset_sensors = f.offset_sensors;
  t.slope_sensors = {"ambient_C", "z_nut_C", "z_motor_C"};
  t.blank_sensor = "ambient_C";
  t.z_ref_mm = 6400;
  t.a.resize(3);
  for (std::size_t j = 0; j < 3; ++j) t.a(j) = f.offset_prior.at(f.offset_sensors[j]);
  t.g.resize(3);
  t.g << f.slope_prior.at("ambient_C"), f.slope_prior.at("z_nut_C"), motor_um_per_1000_per_k;
  t.blank_tau_min = 60;
  t.blank_um_per_1000_per_k = f.blank_prior;
  return t;
}

// MotorTruth with one lag (40 min) on every input, each coefficient on the instant column,
// except z_nut_C's, which acts through the lag only and at 5 times its prior (its 40-min wave,
// seen late, is then a large part of the slope).
drift::GreyBoxModel NutLagTruth(double motor_um_per_1000_per_k) {
  drift::GreyBoxModel t = MotorTruth(motor_um_per_1000_per_k);
  t.time_constants = {40};
  const Eigen::VectorXd a = t.a, g = t.g;
  t.a = Eigen::VectorXd::Zero(6);
  t.g = Eigen::VectorXd::Zero(6);
  for (int j = 0; j < 3; ++j) t.a(2 * j) = a(j), t.g(2 * j) = g(j);
  t.g(2) = 0, t.g(3) = 5 * g(1);
  return t;
}

// probe_extra_um_per_k: the probe readings also grow with head_bearing_C - 20 by this much (a
// law of the idle test that the cuts do not follow, e.g. the probe's own bracket).
// nut_lag: the planted slope follows z_nut_C through a 40-min lag (NutLagTruth).
drift::ShopRecord MotorRecord(int first_day, int days, double motor_um_per_1000_per_k = 25,
                              double probe_extra_um_per_k = 0, bool nut_lag = false) {
  const drift::GreyBoxModel truth =
      nut_lag ? NutLagTruth(motor_um_per_1000_per_k) : MotorTruth(motor_um_per_1000_per_k);
  drift::ShopRecord rec;
  Rng rng(5);
  for (int d = first_day; d < first_day + days; ++d) {
    const int log = static_cast<int>(rec.day_logs.size());
    rec.day_logs.push_back(FieldLikeLog(d));
    std::vector<drift::MeasurementRecord> rs;
    drift::MeasurementRecord probe;
    probe.kind = drift::MeasurementRecord::Kind::kProbe;
    probe.day = d, probe.log = log;
    for (int k = 0; k <= 360; k += 10) probe.rows.push_back({k, double(k), 150.0, 0, 1.0});
    rs.push_back(probe);
    for (int start : {40, 200}) {
      drift::MeasurementRecord lead;
      lead.kind = drift::MeasurementRecord::Kind::kLead;
      lead.day = d, lead.log = log;
      for (int k = 0; k <= 120; k += 5)
        lead.rows.push_back({start + k, double(start + k), 5000.0 - 30.0 * k, 0, 2.0});
      rs.push_back(lead);
    }
    for (auto& r : rs) {
      const std::vector<double> m = drift::PredictGreyRecord(truth, rec, r);
      const double zero = 3 * rng.Normal();
      const bool probe = r.kind == drift::MeasurementRecord::Kind::kProbe;
      const drift::Run& l = rec.day_logs.back();
      for (std::size_t i = 0; i < r.rows.size(); ++i)
        r.rows[i].value_um =
            m[i] + zero +
            (probe ? probe_extra_um_per_k * (l.temperature_C(r.rows[i].sample, 0) - 20) : 0.0);
      rec.records.push_back(std::move(r));
    }
  }
  return rec;
}

// RMS over a record's lead readings of the model's error against the planted truth, each lead
// against its first reading (what a lead measurement holds).
double LeadRms(const drift::GreyBoxModel& m, const drift::ShopRecord& rec,
               double motor_um_per_1000_per_k = 25) {
  const drift::GreyBoxModel truth = MotorTruth(motor_um_per_1000_per_k);
  double s = 0;
  int n = 0;
  for (const auto& r : rec.records) {
    if (r.kind != drift::MeasurementRecord::Kind::kLead) continue;
    const std::vector<double> p = drift::PredictGreyRecord(m, rec, r),
                              t = drift::PredictGreyRecord(truth, rec, r);
    for (std::size_t i = 0; i < p.size(); ++i, ++n) {
      const double e = (p[i] - p[0]) - (t[i] - t[0]);
      s += e * e;
    }
  }
  return std::sqrt(s / n);
}

// grey_all_sensors reads every sensor on both channels: where the slope also follows a sensor the
// field grey box does not read, it predicts new days' leads at least 20 times better than the
// field grey box fitted from the same records, which misses them by more than 20 um (rms).
TEST(GreyCandidates, AllSensorsLearnsASlopeSensorTheFieldGreyBoxLacks) {
  const drift::ShopRecord train = MotorRecord(0, 8), test = MotorRecord(20, 3);
  const std::vector<std::string>& sensors = train.day_logs.front().sensor_names;
  const GreyCandidateFit all = FieldGreyCandidate(6400, false, sensors);
  EXPECT_EQ(all.spec.offset_sensors, sensors);
  EXPECT_EQ(all.spec.slope_sensors, sensors);
  const drift::GreyBoxModel field = drift::FitGreyBox(train, FieldGreyBoxSpec(6400),
                                                      FieldGreyBoxOptions()),
                            cand = drift::FitGreyBox(train, all.spec, all.options);
  const double c = LeadRms(cand, test), f = LeadRms(field, test);
  EXPECT_GT(f, 20.0);
  EXPECT_LT(c, f / 20) << "candidate " << c << " um, field " << f << " um";
}

// The field grey box gives the lead records 0.9 of the weight (the eighth round's row, adopted):
// where the idle probe readings follow a law the cuts do not (an extra 3 um per K of
// head_bearing_C), it predicts new days' leads better than with a share of 0.5 fitted from the
// same records; where the probe tells the truth, both predict them within 0.5 um (rms).
TEST(GreyCandidates, TheLeadShareOf90PercentFollowsTheLeadsWhereTheProbeDisagrees) {
  const GreyCandidateFit heavy{FieldGreyBoxSpec(6400), FieldGreyBoxOptions()};
  EXPECT_EQ(heavy.options.lead_share, 0.9);  // adopted in the eighth round
  for (double extra : {0.0, 3.0}) {
    const drift::ShopRecord train = MotorRecord(0, 8, 0, extra), test = MotorRecord(20, 3, 0, 0);
    drift::GreyBoxOptions half = FieldGreyBoxOptions();
    half.lead_share = 0.5;
    const drift::GreyBoxModel field = drift::FitGreyBox(train, FieldGreyBoxSpec(6400), half),
                              cand = drift::FitGreyBox(train, heavy.spec, heavy.options);
    const double c = LeadRms(cand, test, 0), f = LeadRms(field, test, 0);
    if (extra == 0) {
      EXPECT_LT(c, 0.5);
      EXPECT_LT(f, 0.5);
    } else {
      EXPECT_LT(c, 0.8 * f) << "candidate " << c << " um, field " << f << " um";
    }
  }
}

// The field grey box (both_grey) follows the record's length since the eleventh round, as the
// tenth round's grey_sensors_by_days did: on a planted record of 19 lead days (below
// 2 x forward_days = 20) it is the five physical sensors' model (FieldGreyBoxSpec) bit for bit,
// on one of 20 the every-sensor model (FieldGreyCandidate) bit for bit (every field of the
// model, as written to a file); with grey_five_sensors it is the five sensors' model on both (the
// model before the eleventh round: old figures reproduce). The opt-in rows keep their models:
// grey_all_sensors every sensor, grey_sensors_by_days the default's. The two models differ on
// both records (z_motor_C moves the slope), so the test sees which one was taken.
TEST(GreyCandidates, TheFieldGreyBoxTakesEverySensorFromTwentyLeadDays) {
  EXPECT_EQ(FieldGreyBoxOptions().forward_days, 10);
  for (int days : {19, 20}) {
    const drift::ShopRecord rec = MotorRecord(0, days);
    ASSERT_EQ(drift::LeadDays(rec).size(), static_cast<std::size_t>(days));
    EXPECT_EQ(EverySensorByDays(rec, FieldGreyBoxOptions()), days >= 20);
    const GreyCandidateFit all =
        FieldGreyCandidate(6400, false, rec.day_logs.front().sensor_names);
    const nlohmann::json five = drift::FitGreyBox(rec, FieldGreyBoxSpec(6400),
                                                  FieldGreyBoxOptions()),
                         every = drift::FitGreyBox(rec, all.spec, all.options);
    EXPECT_NE(five, every) << days << " days";
    const ShopModels m = FitShopModels(rec, 6400, {"power_on"}, false, true),
                     old = FitShopModels(rec, 6400, {"power_on"}, false, true, true);
    EXPECT_EQ(nlohmann::json(m.grey), days >= 20 ? every : five) << days << " days";
    EXPECT_EQ(nlohmann::json(old.grey), five) << days << " days";
    for (const ShopModels* s : {&m, &old}) {
      ASSERT_EQ(s->grey_candidates.size(), 5u);
      EXPECT_EQ(nlohmann::json(s->grey_candidates[0]), every) << days << " days";
      EXPECT_EQ(nlohmann::json(s->grey_candidates[1]), days >= 20 ? every : five) << days;
    }
  }
}

// The twelfth round's candidate (grey_short_prior) acts only on a short record: below
// 2 x forward_days = 20 lead days the strength comes from short_record_strength_grid (a value
// the default grid lacks, 7, is the one chosen; ShortRecordStrongPrior fixes 1), from 20 lead
// days on the option changes nothing, bit for bit (every field of the model as written to a
// file), so the 4- and 8-week figures cannot move. The row is that fit of both_grey's spec below
// 20 lead days and both_grey's model itself from 20 on.
TEST(GreyCandidates, TheShortRecordStrengthActsOnlyBelowTwentyLeadDays) {
  const drift::GreyBoxOptions field = FieldGreyBoxOptions();
  EXPECT_TRUE(field.short_record_strength_grid.empty());  // off unless asked for
  EXPECT_EQ(ShortRecordStrongPrior(field).short_record_strength_grid, std::vector<double>{1.0});
  drift::GreyBoxOptions seven = field;
  seven.short_record_strength_grid = {7.0};
  ASSERT_EQ(std::count(field.strength_grid.begin(), field.strength_grid.end(), 7.0), 0);
  for (int days : {19, 20}) {
    const drift::ShopRecord rec = MotorRecord(0, days);
    ASSERT_EQ(drift::LeadDays(rec).size(), static_cast<std::size_t>(days));
    EXPECT_EQ(&drift::StrengthGrid(rec, seven),
              days < 20 ? &seven.short_record_strength_grid : &seven.strength_grid);
    const drift::GreyBoxSpec spec = FieldGreyBoxSpec(6400);
    const drift::GreyBoxModel plain = drift::FitGreyBox(rec, spec, field),
                              strong = drift::FitGreyBox(rec, spec, seven),
                              one = drift::FitGreyBox(rec, spec, ShortRecordStrongPrior(field));
    if (days < 20) {
      EXPECT_EQ(strong.prior_strength, 7.0);
      EXPECT_EQ(one.prior_strength, 1.0);
      EXPECT_NE(nlohmann::json(strong), nlohmann::json(plain));
    } else {
      EXPECT_EQ(nlohmann::json(strong), nlohmann::json(plain));
      EXPECT_EQ(nlohmann::json(one), nlohmann::json(plain));
    }
    const ShopModels m = FitShopModels(rec, 6400, {"power_on"}, false, true);
    ASSERT_EQ(m.grey_candidates.size(), 5u);
    EXPECT_EQ(nlohmann::json(m.grey_candidates[2]), nlohmann::json(days < 20 ? one : m.grey))
        << days << " days";
  }
  EXPECT_EQ(ToString(GreyCandidate::kShortPrior), "grey_short_prior");
  EXPECT_EQ(OptInRowName(kOffsetCandidateCount + kGreyCandidateCount - 3), "grey_guarded");
  EXPECT_EQ(OptInRowName(kOffsetCandidateCount + kGreyCandidateCount - 1), "grey_short_mix_fixed");
}

// The thirteenth round's rows (grey_short_offset_as_read, grey_short_offset_one_lag) act only on
// a short record: below 2 x forward_days = 20 lead days the offset sensors keep their instant
// column and the first `lags` of the chosen lags, the other lag columns' coefficients are exactly
// 0 (the evaluator and the 840D programs then run the model as it is) while the slope channel
// keeps its lags; from 20 lead days on the option changes nothing, bit for bit, so the 4- and
// 8-week figures cannot move. The rows are those fits below 20 lead days, both_grey's model from
// 20 on. The record's slope follows z_nut_C through a 40-min lag, so lags are chosen.
TEST(GreyCandidates, TheShortRecordOffsetLagsActOnlyBelowTwentyLeadDays) {
  const drift::GreyBoxOptions field = FieldGreyBoxOptions();
  EXPECT_EQ(field.short_record_offset_lags, -1);  // off unless asked for
  EXPECT_EQ(ShortRecordOffsetLags(field, 1).short_record_offset_lags, 1);
  const drift::GreyBoxSpec spec = FieldGreyBoxSpec(6400);
  for (int days : {19, 20}) {
    const drift::ShopRecord rec = MotorRecord(0, days, 0, 0, /*nut_lag=*/true);
    ASSERT_EQ(drift::LeadDays(rec).size(), static_cast<std::size_t>(days));
    const drift::GreyBoxModel plain = drift::FitGreyBox(rec, spec, field);
    const ShopModels m = FitShopModels(rec, 6400, {"power_on"}, false, true);
    ASSERT_EQ(m.grey_candidates.size(), 5u);
    for (int lags : {0, 1}) {
      const drift::GreyBoxModel cut =
          drift::FitGreyBox(rec, spec, ShortRecordOffsetLags(field, lags));
      EXPECT_EQ(nlohmann::json(m.grey_candidates[3 + static_cast<std::size_t>(lags)]),
                nlohmann::json(days < 20 ? cut : m.grey))
          << days << " days";
      if (days >= 20) {
        EXPECT_EQ(nlohmann::json(cut), nlohmann::json(plain)) << lags;
        continue;
      }
      const auto taus = static_cast<int>(cut.time_constants.size());
      ASSERT_GE(taus, 1) << "no lag chosen: the test could not fail";
      for (int i = 0; i < 3; ++i) {  // offset sensors: instant, then the lags
        EXPECT_NE(cut.a(i * (1 + taus)), 0.0) << i;
        for (int l = 1; l <= taus; ++l)
          EXPECT_EQ(cut.a(i * (1 + taus) + l) == 0.0, l > lags) << lags << " " << i << " " << l;
      }
      for (int l = 1; l <= taus; ++l) EXPECT_NE(cut.g(l), 0.0) << l;  // the slope keeps its lags
      if (lags < taus)
        EXPECT_NE(nlohmann::json(cut), nlohmann::json(plain)) << lags;
      else  // every chosen lag kept: nothing to drop
        EXPECT_EQ(nlohmann::json(cut), nlohmann::json(plain)) << lags;
    }
  }
  EXPECT_EQ(ToString(GreyCandidate::kShortOffsetAsRead), "grey_short_offset_as_read");
  EXPECT_EQ(ToString(GreyCandidate::kShortOffsetOneLag), "grey_short_offset_one_lag");
}

// LeadDays counts the calendar days with a lead reading: not a probe-only day, not a lead
// record without rows; ScoresForward needs kForwardLeads and 2 x forward_days of them.
TEST(GreyCandidates, LeadDaysCountOnlyDaysWithALeadReading) {
  drift::ShopRecord rec = MotorRecord(0, 4);
  for (drift::MeasurementRecord& r : rec.records)
    if (r.day == 1 && r.kind == drift::MeasurementRecord::Kind::kLead) r.rows.clear();
  for (drift::MeasurementRecord& r : rec.records)
    if (r.day == 2 && r.kind == drift::MeasurementRecord::Kind::kLead)
      r.kind = drift::MeasurementRecord::Kind::kProbe;
  EXPECT_EQ(drift::LeadDays(rec), (std::vector<int>{0, 3}));
  drift::GreyBoxOptions o = FieldGreyBoxOptions();
  o.forward_days = 2;
  EXPECT_FALSE(drift::ScoresForward(rec, o));
  o.forward_days = 1;  // 2 lead days = 2 x 1: scores (the fit validates forward_days, not this)
  EXPECT_TRUE(drift::ScoresForward(rec, o));
  o.validation = drift::GreyValidation::kLeaveOneDayOut;
  EXPECT_FALSE(drift::ScoresForward(rec, o));
}

// The leads of a world where only the time since power-on moves the machine (the sensors of
// FieldLikeLog carry nothing): K0 = 8 um (1 - exp(-t / 60 min)), the slope 6 um per 1000 mm
// times the same, about the field grey box's z_ref of 6400 mm; the records of MotorRecord.
drift::ShopRecord ClockRecord(int first_day, int days) {
  drift::ShopRecord rec = MotorRecord(first_day, days, 0);
  Rng rng(7);
  for (drift::MeasurementRecord& r : rec.records) {
    const double zero = 3 * rng.Normal();
    for (drift::Measurement& m : r.rows) {
      const double rise = 1 - std::exp(-m.time_min / 60);
      m.value_um = zero + 8 * rise + 6 * rise * (6400 - m.z_mm) / 1000;
    }
  }
  return rec;
}

drift::JointSpec WarmupSpec() {
  drift::JointSpec s;
  s.z_ref_mm = 6400;
  s.other_inputs = {"power_on"};
  return s;
}

drift::JointFitOptions WarmupOptions() {
  drift::JointFitOptions o;
  o.require_lag = true;
  return o;
}

// grey_guarded (the ninth round) chooses on the shop's own last two lead days: where the leads
// follow the field grey box's law (the sensors carry the truth) it keeps the grey box, which
// then scores at most a tenth of warmup's rule; where they follow the time since power-on alone
// (the sensors carry nothing) it keeps the rule, which then scores at most half the grey box's.
TEST(GreyGuard, KeepsTheGreyBoxWhereTheSensorsCarryTheTruthAndTheRuleWhereTheyCarryNothing) {
  const GuardScore truth = GuardGreyBox(MotorRecord(0, 8, 0), FieldGreyBoxSpec(6400),
                                        FieldGreyBoxOptions(), WarmupSpec(), WarmupOptions());
  EXPECT_EQ(truth.days, 2);
  EXPECT_TRUE(truth.keep_grey);
  EXPECT_LT(truth.grey_rms_um, truth.rule_rms_um / 10)
      << truth.grey_rms_um << " / " << truth.rule_rms_um;
  const GuardScore clock = GuardGreyBox(ClockRecord(0, 8), FieldGreyBoxSpec(6400),
                                        FieldGreyBoxOptions(), WarmupSpec(), WarmupOptions());
  EXPECT_EQ(clock.days, 2);
  EXPECT_FALSE(clock.keep_grey);
  EXPECT_LT(clock.rule_rms_um, clock.grey_rms_um / 2)
      << clock.rule_rms_um << " / " << clock.grey_rms_um;
}

// No look-ahead within the record: each held day is predicted from the days before it only, so
// the last day's other records (the probe at power-on) never enter a fit, and a lead is scored
// about its own mean (its zero is unknown): changing both leaves the scores equal (to rounding).
// Where no day can be scored (a single day: nothing before it) the grey box stays.
TEST(GreyGuard, ScoresEachHeldDayFromTheDaysBeforeItOnly) {
  const drift::ShopRecord rec = MotorRecord(0, 6, 0);
  drift::ShopRecord changed = rec;
  for (drift::MeasurementRecord& r : changed.records) {
    if (r.day < 5) continue;
    const bool lead = r.kind == drift::MeasurementRecord::Kind::kLead;
    for (drift::Measurement& m : r.rows) m.value_um += lead ? 50.0 : 30.0 * m.time_min;
  }
  const GuardScore a = GuardGreyBox(rec, FieldGreyBoxSpec(6400), FieldGreyBoxOptions(),
                                    WarmupSpec(), WarmupOptions()),
                   b = GuardGreyBox(changed, FieldGreyBoxSpec(6400), FieldGreyBoxOptions(),
                                    WarmupSpec(), WarmupOptions());
  EXPECT_EQ(a.days, 2);
  EXPECT_NEAR(a.grey_rms_um, b.grey_rms_um, 1e-9);
  EXPECT_NEAR(a.rule_rms_um, b.rule_rms_um, 1e-9);
  const GuardScore one = GuardGreyBox(ClockRecord(0, 1), FieldGreyBoxSpec(6400),
                                      FieldGreyBoxOptions(), WarmupSpec(), WarmupOptions());
  EXPECT_EQ(one.days, 0);
  EXPECT_TRUE(one.keep_grey);
  EXPECT_EQ(one.combination_weight, 1.0);
}

// grey_short_mix (the fourteenth round) takes the least-squares weight of the grey box on the
// guard's held days: near 1 where the leads follow the field grey box's law (the sensors carry
// the truth), below the floor where they follow the time since power-on alone (the sensors carry
// nothing), where ShortMixWeights then keeps the floor 0.5: the grey box is never dropped. On a
// long record both weights are 1 (both_grey's line), on a short one the fixed row's is 0.75.
TEST(GreyMix, TheCombinationWeightFollowsWhichFamilyCarriesTheLeads) {
  const GuardScore truth = GuardGreyBox(MotorRecord(0, 8, 0), FieldGreyBoxSpec(6400),
                                        FieldGreyBoxOptions(), WarmupSpec(), WarmupOptions());
  EXPECT_NEAR(truth.combination_weight, 1.0, 0.1);
  const GuardScore clock = GuardGreyBox(ClockRecord(0, 8), FieldGreyBoxSpec(6400),
                                        FieldGreyBoxOptions(), WarmupSpec(), WarmupOptions());
  EXPECT_LT(clock.combination_weight, kShortMixFloor);
  const ShopModels::Mix short_clock = ShortMixWeights(false, clock);
  EXPECT_EQ(short_clock.fitted_weight, kShortMixFloor);
  EXPECT_EQ(short_clock.fixed_weight, 0.75);
  EXPECT_EQ(ShortMixWeights(false, truth).fitted_weight,
            std::min(1.0, truth.combination_weight));
  for (const GuardScore& g : {truth, clock}) {
    const ShopModels::Mix long_record = ShortMixWeights(true, g);
    EXPECT_EQ(long_record.fitted_weight, 1.0);
    EXPECT_EQ(long_record.fixed_weight, 1.0);
  }
  EXPECT_EQ(ToString(GreyCandidate::kShortMix), "grey_short_mix");
  EXPECT_EQ(ToString(GreyCandidate::kShortMixFixed), "grey_short_mix_fixed");
}

// grey_guarded scores the model it applies (both_grey's): on a record of 20 lead days the
// every-sensor grey box's guard score, on 19 days and with grey_five_sensors the five sensors'.
// The two specs' scores differ on both records, so the test sees which one was scored.
TEST(GreyGuard, ScoresTheGreyBoxItApplies) {
  for (int days : {19, 20}) {
    const drift::ShopRecord rec = MotorRecord(0, days);
    const GreyCandidateFit all =
        FieldGreyCandidate(6400, false, rec.day_logs.front().sensor_names);
    const GuardScore every = GuardGreyBox(rec, all.spec, FieldGreyBoxOptions(), WarmupSpec(),
                                          WarmupOptions()),
                     five = GuardGreyBox(rec, FieldGreyBoxSpec(6400), FieldGreyBoxOptions(),
                                         WarmupSpec(), WarmupOptions());
    ASSERT_EQ(every.days, 2);
    EXPECT_NE(every.grey_rms_um, five.grey_rms_um) << days << " days";
    const ShopModels m = FitShopModels(rec, 6400, {"power_on"}, false, true),
                     old = FitShopModels(rec, 6400, {"power_on"}, false, true, true);
    ASSERT_TRUE(m.guard.chosen);
    EXPECT_EQ(m.guard.grey_rms_um, (days >= 20 ? every : five).grey_rms_um) << days << " days";
    EXPECT_EQ(m.guard.keep_grey, (days >= 20 ? every : five).keep_grey) << days << " days";
    EXPECT_EQ(old.guard.grey_rms_um, five.grey_rms_um) << days << " days";
    EXPECT_EQ(m.guard.rule_rms_um, five.rule_rms_um) << days << " days";
    // The fourteenth round's weights act only below 20 lead days (from the same guard score).
    const ShopModels::Mix expect = ShortMixWeights(days >= 20, days >= 20 ? every : five);
    EXPECT_EQ(m.mix.fitted_weight, expect.fitted_weight) << days << " days";
    EXPECT_EQ(m.mix.fixed_weight, days >= 20 ? 1.0 : kShortMixFixedWeight) << days << " days";
    if (days >= 20) {
      EXPECT_EQ(m.mix.fitted_weight, 1.0);
    }
  }
}

// A record whose leads follow both families: MotorRecord's sensor law (no motor term) plus `share` of
// ClockRecord's time since power-on (8 um and 6 um per 1000 mm times 1 - exp(-t / 60 min)).
drift::ShopRecord BlendRecord(int days, double share) {
  drift::ShopRecord rec = MotorRecord(0, days, 0);
  for (drift::MeasurementRecord& r : rec.records)
    for (drift::Measurement& m : r.rows) {
      const double rise = 1 - std::exp(-m.time_min / 60);
      m.value_um += share * (8 * rise + 6 * rise * (6400 - m.z_mm) / 1000);
    }
  return rec;
}

// The shop's path (drift/grey_mix.h FitGreyMix, what whirl drift fit-grey runs) gives the lab's
// grey_short_mix on the same record: the same base rule and the same w where the sensors carry
// the leads (w near 1), where the clock does (w at the floor) and where both do (blends; at least
// one w strictly between the floor and 1, so the clamp hides no difference). From 20 lead days on
// neither mixes.
TEST(GreyMix, TheShopsMixIsTheLabsOnTheSameRecord) {
  std::vector<double> weights;
  std::vector<drift::ShopRecord> records = {MotorRecord(0, 8, 0), ClockRecord(0, 8)};
  for (double share : {0.5, 0.2, 0.1, 0.05}) records.push_back(BlendRecord(8, share));
  for (const drift::ShopRecord& rec : records) {
    const ShopModels lab = FitShopModels(rec, 6400, {"power_on"}, false, false, false, true);
    const drift::GreyMix shop =
        drift::FitGreyMix(rec, FieldGreyBoxSpec(6400), FieldGreyBoxOptions(), {"power_on"});
    ASSERT_TRUE(shop.applies);
    ASSERT_TRUE(lab.mix.applied);
    EXPECT_EQ(shop.weight, lab.mix.fitted_weight);
    EXPECT_EQ(shop.rules.is_schedule, lab.rule_is_schedule);
    EXPECT_EQ(shop.rules.Base().cv_rmse_um,
              (lab.rule_is_schedule ? lab.schedule : lab.warmup).cv_rmse_um);
    EXPECT_EQ(shop.guard.days, 2);
    weights.push_back(shop.weight);
  }
  EXPECT_GT(weights[0], 0.9);
  EXPECT_EQ(weights[1], kShortMixFloor);
  EXPECT_TRUE(std::any_of(weights.begin() + 2, weights.end(),
                          [](double w) { return w > kShortMixFloor && w < 1.0; }))
      << "no blend gave a weight strictly inside (0.5, 1): " << ::testing::PrintToString(weights);
  const drift::GreyMix long_record =
      drift::FitGreyMix(MotorRecord(0, 20), FieldGreyBoxSpec(6400), FieldGreyBoxOptions());
  EXPECT_FALSE(long_record.applies);
  EXPECT_EQ(long_record.weight, 1.0);
}

// The model file's mix part (drift/grey_box_io.h): written as schema_version 2, read back to the
// number; the rule's models are the lab's (ShopControlModels over the record's day logs). A
// version 1 file with a mix, a version 2 file without one, a weight outside [0.5, 1), another
// rule or a rule reading sensors are refused with the field's name.
TEST(GreyMix, TheModelFilesMixPartRoundTripsAndBadPartsAreRefused) {
  const drift::ShopRecord rec = ClockRecord(0, 8);
  const drift::GreyBoxOptions options = FieldGreyBoxOptions();
  const drift::GreyMix mix = drift::FitGreyMix(rec, FieldGreyBoxSpec(6400), options, {"power_on"});
  drift::GreyBoxFile file{drift::FitGreyBox(rec, FieldGreyBoxSpec(6400), options),
                          drift::GreyBoxMixPart(mix, rec)};
  ASSERT_TRUE(file.mix);
  EXPECT_EQ(file.mix->weight, kShortMixFloor);
  const ShopControl lab = ShopControlModels(mix.rules.Base(), rec.day_logs);
  EXPECT_EQ(file.mix->rule_offset.linear.coefficients, lab.offset.linear.coefficients);
  EXPECT_EQ(file.mix->rule_slope.linear.coefficients, lab.slope.linear.coefficients);
  EXPECT_EQ(file.mix->rule_offset.feature_max, lab.offset.feature_max);
  const auto dir = test::ScratchDir() / "grey_mix_file";
  std::filesystem::create_directories(dir);
  drift::WriteGreyBoxFile(dir / "mix.json", file);
  const drift::GreyBoxFile back = drift::ReadGreyBoxFile(dir / "mix.json");
  ASSERT_TRUE(back.mix);
  EXPECT_EQ(back.mix->weight, file.mix->weight);
  EXPECT_EQ(back.mix->rule, mix.rules.BaseName());
  EXPECT_EQ(back.mix->guard.combination_weight, mix.guard.combination_weight);
  EXPECT_EQ(nlohmann::json(back.mix->rule_offset), nlohmann::json(file.mix->rule_offset));
  EXPECT_EQ(nlohmann::json(back.mix->rule_slope), nlohmann::json(file.mix->rule_slope));
  EXPECT_EQ(nlohmann::json(back.model), nlohmann::json(file.model));
  const nlohmann::json j = ReadJsonFile(dir / "mix.json");
  EXPECT_EQ(j["schema_version"], 2);
  // Without the mix: version 1, the file as before.
  drift::WriteGreyBoxFile(dir / "alone.json", {file.model, std::nullopt});
  EXPECT_EQ(ReadJsonFile(dir / "alone.json")["schema_version"], 1);
  EXPECT_FALSE(drift::ReadGreyBoxFile(dir / "alone.json").mix);
  const auto refused = [&](nlohmann::json bad, const std::string& what) {
    const auto path = dir / "bad.json";
    WriteJsonFile(path, bad);
    const std::string error = ErrorOf([&] { (void)drift::ReadGreyBoxFile(path); });
    EXPECT_NE(error.find(what), std::string::npos) << error;
    EXPECT_NE(error.find("bad.json"), std::string::npos) << error;
  };
  nlohmann::json v1 = j;
  v1["schema_version"] = 1;
  refused(v1, "schema_version");
  nlohmann::json no_mix = j;
  no_mix.erase("mix");
  refused(no_mix, "schema_version");
  for (double w : {1.0, 0.4}) {
    nlohmann::json bad = j;
    bad["mix"]["weight"] = w;
    refused(bad, "'weight'");
  }
  nlohmann::json rule = j;
  rule["mix"]["rule"] = "sensors";
  refused(rule, "warmup or schedule");
  nlohmann::json sensors = j;
  const drift::ShopRecord motor = MotorRecord(0, 8, 0);  // the sensors carry it: a sensor model
  drift::DriftModel sensor_model =
      ShopControlModels(FitShopModels(motor, 6400, {"power_on"}).sensors, motor.day_logs).offset;
  ASSERT_FALSE(sensor_model.sensors.empty());
  sensor_model.linear.vif = Eigen::VectorXd::Ones(sensor_model.linear.coefficients.size() - 1);
  sensors["mix"]["rule_offset"] = nlohmann::json(sensor_model);
  refused(sensors, "sensor-free");
}

}  // namespace
}  // namespace whirl::machine_eval
