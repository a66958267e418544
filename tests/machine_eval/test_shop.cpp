// Training from shop measurements and causal application (machine_eval/history.h,
// machine_eval/strategies.h), the legacy evaluation's reproduction, and the seeds summary.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/process.h"
#include "core/random.h"
#include "drift/fit.h"
#include "machine/machine.h"
#include "machine_eval/history.h"
#include "machine_eval/machine_eval.h"
#include "machine_eval/seeds.h"
#include "machine_eval/strategies.h"
#include "machine_eval/trained_numbers.h"
#include "workpiece/model.h"
#include "screw/screw.h"

namespace whirl::machine_eval {
namespace {

using testing_support::TrainedNumbers;

std::string Source(const std::string& rel) { return std::string(WHIRL_SOURCE_DIR) + "/" + rel; }

// The training runs of one legacy machine (idle, then cutting) with their speeds.
struct Training {
  std::vector<drift::Run> runs;
  std::vector<double> speeds = {0, 0, 170, 190};
};
Training LegacyTraining(std::uint64_t machine_seed) {
  const machine::MachineConfig c = machine::DefaultMachine();
  Training t;
  t.runs = TrainingRuns(c, machine_seed, 2, drift::RunState::kIdle);
  const auto cutting = TrainingRuns(c, machine_seed, 2, drift::RunState::kCutting);
  t.runs.insert(t.runs.end(), cutting.begin(), cutting.end());
  return t;
}

nlohmann::json Trained(const ShopModels& s) {
  return {TrainedNumbers(s.sensors), TrainedNumbers(s.warmup), TrainedNumbers(s.schedule)};
}

// No truth channel reaches a model: 20 um pulses added to the runs' exact error channels at the
// minutes between the instruments' readings (probe every 10 min, laser every 20 min) change
// nothing the shop models learn; the same pulses change the legacy models, which read the
// channels every minute (the control that shows the pulses are large enough to matter).
TEST(ShopTraining, PulsesInTheTruthBetweenReadingsChangeNothingTrained) {
  const double z_fixed = machine::DefaultMachine().z_screw.fixed_end_mm;
  const Training clean = LegacyTraining(MixSeed(1, 0x4d00));
  Training pulsed = clean;
  for (auto& run : pulsed.runs)
    for (int k = 0; k < run.samples(); ++k)
      if (std::fmod(run.time_min[static_cast<std::size_t>(k)], 10.0) != 0.0)
        run.error_um.row(k).array() += 20.0 * ((k % 3) - 1);
  const ShopProtocol p;
  const drift::ShopRecord a = MeasureTrainingRuns(clean.runs, clean.speeds, z_fixed, p, 7);
  const drift::ShopRecord b = MeasureTrainingRuns(pulsed.runs, pulsed.speeds, z_fixed, p, 7);
  for (const auto& log : b.day_logs) EXPECT_TRUE(log.error_names.empty());
  EXPECT_EQ(Trained(FitShopModels(a, z_fixed)).dump(), Trained(FitShopModels(b, z_fixed)).dump());
  drift::FitOptions f;
  f.threads = 1;
  const std::vector<drift::Run> cut_clean(clean.runs.begin() + 2, clean.runs.end());
  const std::vector<drift::Run> cut_pulsed(pulsed.runs.begin() + 2, pulsed.runs.end());
  EXPECT_NE(drift::FitDriftModel(cut_clean, "offset_um", f).model.linear.coefficients(0),
            drift::FitDriftModel(cut_pulsed, "offset_um", f).model.linear.coefficients(0));
}

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
// columns as ControlDayLog writes them), probe readings at z = 150 mm every 10 min, and on the
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
    const ShopModels m = FitShopModels(rec, 6400);
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

// The legacy world reproduces the table of the program before this change: per screw, the rows
// none, workpiece, machine, both, both_idle and both_monitor, and the old "traditional" (the
// class means, now the row `class`) equal the reference written by that program
// (`whirl machine evaluate --machines 2 --screws 2 --seed 1 --json` at main 9437d1a) within
// relative 1e-9.
TEST(LegacyWorld, ReproducesTheTableOfThePreviousProgram) {
  std::ifstream in(Source("tests/machine_eval/data/legacy_eval_2x2_seed1.json"));
  ASSERT_TRUE(in.good());
  nlohmann::json ref;
  in >> ref;
  MachineEvalOptions o;
  o.machine = machine::ReadMachine(Source("datasets/machines/whirling_thermal.json"));
  o.machines = 2;
  o.screws_per_machine = 2;
  o.seed = 1;
  const workpiece::WorkpieceModel model =
      workpiece::LoadWorkpieceModel(Source("models/default.json"));
  const compare::ExperienceRule rule =
      compare::BuildExperienceRule(ReadProcessTable(Source("datasets/whirling_500.csv"), true));
  const lead::IsoToleranceTable iso =
      lead::ReadIsoToleranceTable(Source("datasets/standards/iso3408_3_lead_tolerances.csv"));
  const MachineEvaluation e = EvaluateWithMachines(
      screw::ReadScrew(Source("datasets/screws/reference_80x10x6000.json")), model, rule, iso, o);
  nlohmann::json now = e;
  ASSERT_EQ(ref["screws"].size(), now["screws"].size());
  const std::vector<std::pair<std::string, std::string>> rows = {
      {"none", "none"}, {"workpiece", "workpiece"}, {"machine", "machine"},
      {"both", "both"}, {"both_idle", "both_idle"}, {"both_monitor", "both_monitor"},
      {"traditional", "class"}};
  for (std::size_t s = 0; s < now["screws"].size(); ++s)
    for (const auto& [old_name, new_name] : rows)
      for (const char* metric : {"accumulated_1000_um", "accumulated_total_um", "e_a_um"}) {
        const double a = ref["screws"][s]["strategies"][old_name]["metrics"][metric];
        const double b = now["screws"][s]["strategies"][new_name]["metrics"][metric];
        EXPECT_NEAR(a, b, 1e-9 * (1 + std::abs(a))) << s << " " << new_name << " " << metric;
      }
}

// The headline names the sensor-free row with the smallest pooled thread median (none excluded,
// sensor rows never), and the per-seed medians bound the pooled one.
TEST(SeedsSummary, StrongestSensorFreeIsTheSmallestThreadMedianWithoutSensors) {
  std::array<SeedStats, kMachineStrategyCount> s{};
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) s[k].total_median_um = 50.0 - k;
  s[static_cast<std::size_t>(MachineStrategy::kNone)].total_median_um = 0.1;
  EXPECT_EQ(StrongestSensorFree(s), MachineStrategy::kSchedule);  // 39: the smaller values are sensor rows
  s[static_cast<std::size_t>(MachineStrategy::kTable)].total_median_um = 5;
  EXPECT_EQ(StrongestSensorFree(s), MachineStrategy::kTable);
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    if (UsesSensors(static_cast<MachineStrategy>(k))) s[k].total_median_um = 0.01;
  EXPECT_EQ(StrongestSensorFree(s), MachineStrategy::kTable);
}

}  // namespace
}  // namespace whirl::machine_eval
