// Training from shop measurements and causal application (machine_eval/shop_models.h,
// machine_eval/strategies.h), and the seeds summary. That no truth reaches a trained model is
// tested on the field world (test_field_eval.cpp, FieldTraining).
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/random.h"
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

}  // namespace
}  // namespace whirl::machine_eval
