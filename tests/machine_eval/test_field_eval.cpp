// The field world's evaluation (machine_eval/field_eval.h, field_history.h): no truth reaches a
// trained model, no look-ahead in the applied compensation, the headlines over seeds.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <nlohmann/json.hpp>

#include "core/random.h"
#include "machine/instruments.h"
#include "machine/scenarios.h"
#include "machine/truth.h"
#include "machine_eval/field_eval.h"
#include "machine_eval/field_history.h"
#include "machine_eval/seeds.h"
#include "machine_eval/strategies.h"

namespace whirl::machine_eval {
namespace {

// A small calendar: one warm-up test, one laser test, two past production days, one test day.
machine::CalendarSpec SmallCalendar() {
  machine::CalendarSpec c;
  c.warmup_speeds_m_min = {180};
  c.past_days = 2;
  c.test_days = 1;
  return c;
}

machine::MachineWorld SmallWorld(const machine::TimelineOptions& options, std::uint64_t seed = 3) {
  return machine::BuildMachineWorld(machine::DefaultFieldMachine(),
                                    machine::FindMachineScenario("duty-changes"), seed, 0,
                                    SmallCalendar(), options);
}

// Every trained number of a joint model: inputs, time constants, coefficients, the CV.
nlohmann::json Trained(const drift::JointDriftModel& m) {
  return {{"sensors", m.sensors},
          {"others", m.other_inputs},
          {"taus", m.time_constants},
          {"a", std::vector<double>(m.a.data(), m.a.data() + m.a.size())},
          {"g", std::vector<double>(m.g.data(), m.g.data() + m.g.size())},
          {"cv", m.cv_rmse_um}};
}
nlohmann::json Trained(const FieldMachineModels& f) {
  return {Trained(f.shop.sensors), Trained(f.shop.warmup), Trained(f.shop.schedule),
          f.shop.sensors_choice, f.records, f.readings};
}

// No truth channel reaches a model: doubling every heat source and warming the hall by 3 K from
// day 0 on (the test window, after the history) changes the truth of the test day by several um
// but nothing that was trained (coefficients, sensors, lags, CV, the record's size). A record
// that read a day of the test window would see it.
TEST(FieldTraining, HiddenTruthOfTheTestWindowChangesNothingTrained) {
  machine::TimelineOptions changed;
  changed.test_window_power_factor = 2.0;
  changed.test_window_hall_offset_k = 3.0;
  const machine::MachineWorld a = SmallWorld({}), b = SmallWorld(changed);
  const FieldProtocol p;
  const FieldMachineModels ma = TrainFieldMachine(a.timeline, p, nullptr, 7);
  const FieldMachineModels mb = TrainFieldMachine(b.timeline, p, nullptr, 7);
  EXPECT_EQ(Trained(ma).dump(), Trained(mb).dump());
  // The control: the perturbation is large where it applies.
  const machine::DayPlan& test = a.timeline.Day(0);
  ASSERT_FALSE(test.jobs.empty());
  const machine::TruthSample ta = machine::TrueError(a.timeline, test.jobs[0].cut_end_min, 3000);
  const machine::TruthSample tb = machine::TrueError(b.timeline, test.jobs[0].cut_end_min, 3000);
  EXPECT_GT(std::abs(ta.total_um() - tb.total_um()), 2.0);
  EXPECT_GT(ma.records, 4);
}

// The record holds only instrument readings: probe, laser, lead and set-up check records of days
// before 0, each row a sample of its own day log, no error channel in any log.
TEST(FieldTraining, TheRecordHasOnlyReadingsOfHistoryDays) {
  const machine::MachineWorld w = SmallWorld({});
  const drift::ShopRecord r = FieldShopRecord(w.timeline, FieldProtocol{}, nullptr, 5);
  EXPECT_NO_THROW(r.Validate());
  std::set<drift::MeasurementRecord::Kind> kinds;
  for (const auto& rec : r.records) {
    EXPECT_LT(rec.day, 0) << rec.name;
    kinds.insert(rec.kind);
  }
  EXPECT_EQ(kinds.size(), 4u);
  for (const auto& log : r.day_logs) EXPECT_TRUE(log.error_names.empty()) << log.name;
}

// No look-ahead on the field world: the models trained on the history, run on the test day's
// control log through the control's input filter (AverageSensors); replacing every sample after i (sensors +5 K, duty doubled) leaves the applied
// compensation before sample i + 1 exactly unchanged, for every model and random i.
TEST(FieldCausal, TheAppliedValueAtSampleIDependsOnlyOnSamplesUpToI) {
  const machine::MachineWorld w = SmallWorld({});
  const FieldMachineModels m = TrainFieldMachine(w.timeline, FieldProtocol{}, nullptr, 7);
  const machine::DayPlan& day = w.timeline.Day(0);
  const drift::Run log = machine::ControlLog(w.timeline, 0, 11);
  const double start = day.jobs[0].cut_start_min;
  auto z = [](double t_s) { return 5000 - 0.6 * t_s; };
  Rng rng(23);
  for (const drift::JointDriftModel* model : {&m.shop.sensors, &m.shop.warmup, &m.shop.schedule}) {
    const compare::CompensationFunction c =
        CausalMachineLine(RunCausally(*model, AverageSensors(log, 5)), start, m.z_ref_mm, z);
    for (int trial = 0; trial < 10; ++trial) {
      const auto lo = static_cast<int>((start - log.time_min.front()) * 6);
      const int i = lo + 1 + static_cast<int>(rng.Uniform() * 500);
      ASSERT_LT(i + 1, log.samples());
      drift::Run later = log;
      for (int k = i + 1; k < later.samples(); ++k) {
        for (int s = 0; s < later.temperature_C.cols(); ++s) later.temperature_C(k, s) += 5;
        for (int s = 0; s < later.other.cols(); ++s) later.other(k, s) *= 2;
      }
      const compare::CompensationFunction d =
          CausalMachineLine(RunCausally(*model, AverageSensors(later, 5)), start, m.z_ref_mm, z);
      const double t_next_s = (log.time_min[static_cast<std::size_t>(i) + 1] - start) * 60.0;
      for (int q = 0; q < 20; ++q) {
        const double t = rng.Uniform() * t_next_s * (1 - 1e-12);
        ASSERT_EQ(c(t), d(t)) << "i " << i << " t " << t;
      }
      if (!model->sensors.empty() || !model->other_inputs.empty())
        EXPECT_NE(c(t_next_s + 1e-6), d(t_next_s + 1e-6)) << "the change shows from i + 1 on";
    }
  }
}

// A planted evaluation over three seeds: each seed one screw per strategy row, thread error
// planted per strategy (and seed).
SeedsEvaluation Planted(const std::vector<double>& per_strategy, double both_shop_seed_scale) {
  SeedsEvaluation e;
  e.scenario = "planted";
  e.rows = FieldStrategies();
  for (int s = 0; s < 3; ++s) {
    e.seeds.push_back(static_cast<std::uint64_t>(s + 1));
    MachineEvaluation run;
    MachineEvalScrew screw;
    screw.ok = true;
    for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
      double v = per_strategy[k] * (1 + 0.1 * s);
      if (static_cast<MachineStrategy>(k) == MachineStrategy::kBothShop)
        v *= std::pow(both_shop_seed_scale, s);
      screw.metrics[k].accumulated_total_um = v;
      screw.metrics[k].accumulated_1000_um = v / 2;
    }
    run.screws.push_back(screw);
    e.runs.push_back(run);
  }
  return e;
}

// T: headlines name the smallest thread median among the sensor-free rows of the table (rows
// outside the table never), give the gain of both_shop with its per-seed range, and say plainly
// whether the sensors beat it.
TEST(FieldSeedsSummary, HeadlinesNameTheStrongestSensorFreeRowAndTheGain) {
  // none traditional workpiece machine both both_idle both_monitor class table nearest warmup
  // schedule machine_shop both_shop
  std::vector<double> v = {60, 40, 30, 1, 1, 1, 1, 45, 42, 41, 25, 20, 18, 15};
  SeedsEvaluation e = Planted(v, 1.0);
  auto h = MachineHeadlines(e);
  ASSERT_GE(h.size(), 3u);
  EXPECT_NE(h[0].find("strongest sensor-free strategy is schedule"), std::string::npos) << h[0];
  // Gain 1 - 15 / 20 = 25 % in every seed (the seeds scale both rows alike).
  EXPECT_NE(h[1].find("both_shop vs schedule over the thread: +25.0 % (per seed +25.0 .. +25.0"),
            std::string::npos)
      << h[1];
  EXPECT_NE(h[2].find("beats the strongest sensor-free strategy schedule over the thread by 25.0 "
                      "% (better in 3 of 3 seeds)"),
            std::string::npos)
      << h[2];
  // Per-seed range: both_shop x 1, 1.5, 2.25 over the seeds against schedule x 1: gains
  // 1 - 15 (1 + 0.1 s) 1.5^s / (20 (1 + 0.1 s)) = +25, -12.5, -68.75 %.
  e = Planted(v, 1.5);
  h = MachineHeadlines(e);
  EXPECT_NE(h[1].find("(per seed -68.8 .. +25.0 %"), std::string::npos) << h[1];
  EXPECT_NE(h[2].find("does NOT beat"), std::string::npos) << h[2];
  // A sensor-free row outside the table is never named; a sensor row never either.
  v[static_cast<std::size_t>(MachineStrategy::kNearest)] = 10;
  e = Planted(v, 1.0);
  e.rows.erase(std::find(e.rows.begin(), e.rows.end(), MachineStrategy::kNearest));
  h = MachineHeadlines(e);
  EXPECT_NE(h[0].find("is schedule"), std::string::npos) << h[0];
  e.rows = FieldStrategies();
  h = MachineHeadlines(e);
  EXPECT_NE(h[0].find("is nearest"), std::string::npos) << h[0];
  const std::string table = FormatSeedsTable(e, true);
  EXPECT_EQ(table.find("| planted | both_idle |"), std::string::npos);
  EXPECT_NE(table.find("| planted | both_shop |"), std::string::npos);
}

}  // namespace
}  // namespace whirl::machine_eval
