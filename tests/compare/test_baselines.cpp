// Issue 11: the history baselines (compare/traditional.h) and the scenario disturbances
// (sim/simulator.h) against closed forms and hand-computed examples.
#include <gtest/gtest.h>

#include <cmath>

#include "compare/scenarios.h"
#include "compare/traditional.h"
#include "core/error.h"
#include "core/random.h"
#include "sim/simulator.h"

namespace whirl::compare {
namespace {

// A history whose features are exact power laws of the inputs: the regression recovers them.
TEST(Baselines, LogLinearRegressionRecoversAnExactPowerLaw) {
  ProcessTable h;
  h.source = "power_law";
  Rng rng(3);
  auto law = [](const ProcessInputs& p) {
    return Features{2.0 * std::pow(p.hardness_hrc, 0.5) * std::pow(p.diameter_mm, 0.8) *
                        std::pow(p.pitch_mm, -0.6) * std::pow(p.raceway_radius_mm, 0.9) *
                        std::pow(p.cutting_speed_m_min, -1.1),
                    7e5 * std::pow(p.diameter_mm, 2.0) * std::pow(p.cutting_speed_m_min, -2.0) *
                        std::pow(p.pitch_mm, -0.1)};
  };
  for (int i = 0; i < 30; ++i) {
    const ProcessInputs p{60 + 5 * rng.Uniform(), 50 + 50 * rng.Uniform(), 6 + 10 * rng.Uniform(),
                          3 + 7 * rng.Uniform(), 150 + 60 * rng.Uniform()};
    h.inputs.push_back(p);
    h.targets.push_back(law(p));
  }
  const LogLinearFeatures f = FitLogLinear(h);
  EXPECT_NEAR(f.coef[0][2], 0.8, 1e-9);
  EXPECT_NEAR(f.coef[0][5], -1.1, 1e-9);
  EXPECT_NEAR(f.coef[1][2], 2.0, 1e-9);
  EXPECT_NEAR(f.coef[1][1], 0.0, 1e-9);
  const ProcessInputs q{62, 80, 10, 3.7, 180};
  EXPECT_NEAR(f.Predict(q).max_elongation_um, law(q).max_elongation_um,
              1e-9 * law(q).max_elongation_um);
  EXPECT_NEAR(f.Predict(q).settle_time_s, law(q).settle_time_s, 1e-9 * law(q).settle_time_s);
  h.inputs.resize(5);
  h.targets.resize(5);
  EXPECT_THROW(FitLogLinear(h), InputError);  // 5 rows < 6 coefficients
}

// Hand-computed class means: two 80 mm screws and one 50 mm screw.
TEST(Baselines, TraditionalUsesTheClassMeanPlateauAndSettleTime) {
  ProcessTable h;
  h.source = "hand";
  h.inputs = {{62, 80, 10, 3.7, 180}, {62, 82, 10, 3.7, 180}, {62, 50, 10, 3.7, 180}};
  h.targets = {{10, 200}, {14, 300}, {20, 100}};
  const ExperienceRule r = BuildExperienceRule(h);
  EXPECT_DOUBLE_EQ(r.ClassFeatures(80).max_elongation_um, 12);
  EXPECT_DOUBLE_EQ(r.ClassFeatures(80).settle_time_s, 250);
  EXPECT_DOUBLE_EQ(r.ClassFeatures(52).settle_time_s, 100);
  // An empty class falls back to the machine means (plateau 44/3 um, settle 200 s).
  EXPECT_DOUBLE_EQ(r.ClassFeatures(100).settle_time_s, 200);
  EXPECT_FALSE(r.has_regression);  // 3 rows < 6 coefficients
  EXPECT_NE(r.regression_error.find("at least 6"), std::string::npos);
}

// Energy balance of the scenario knobs: tool wear adds w/2 of the cut's heat (linear rise), a
// steady rest adds its power times the heating time.
TEST(Baselines, ToolWearAndSteadyRestHeatFollowTheirClosedForms) {
  const sim::Screw screw = sim::ReferenceScrew();
  sim::SimOptions o;
  o.duration_s = 600;
  o.cell_size_mm = 4;
  sim::DisturbanceOptions d;
  d.enabled = true;
  d.workpiece_variation = d.ambient_drift = d.measurement_noise = false;
  const sim::SimulationResult base = sim::Simulate(screw, o, d);
  const double cut_time = base.kinematics.cutting_time_s;
  sim::DisturbanceOptions wear = d;
  wear.tool_wear_heat_rise_rel = 0.2;
  const double heat_wear = sim::Simulate(screw, o, wear).summary.heat_in_j;
  // Step n deposits the window [n - 0.5, n + 0.5] s (sim/simulator.cpp), so heat flows over
  // [0.5, 600.5]: integral q (1 + 0.2 t / T) dt = q 600 (1 + 0.1 (600.5^2 - 0.5^2) / (600 T))
  // = q 600 (1 + 0.1 * 601 / T).
  const double heated = 600.0;
  EXPECT_NEAR(heat_wear / base.summary.heat_in_j, 1 + 0.1 * 601.0 / cut_time, 1e-9);
  sim::DisturbanceOptions rest = d;
  rest.steady_rest_heat_w = 60;
  const sim::SimulationResult with_rest = sim::Simulate(screw, o, rest);
  EXPECT_NEAR(with_rest.summary.heat_in_j - base.summary.heat_in_j, 60.0 * heated, 1e-6 * 36000);
  EXPECT_GT(with_rest.features.max_elongation_um, base.features.max_elongation_um);
}

TEST(Baselines, ScenarioSelectionAndOutOfRangeScrews) {
  EXPECT_EQ(SelectScenarios("all").size(), NamedScenarios().size());
  EXPECT_EQ(SelectScenarios("tool-wear,today").front().name, "tool-wear");
  EXPECT_THROW(SelectScenarios("today,bogus"), InputError);
  const Scenario out = SelectScenarios("out-of-range").front();
  const InputRanges training;
  for (const auto& s : ScenarioScrews(out, sim::ReferenceScrew(), 20, 9)) {
    const auto& p = s.process;
    const bool outside = p.diameter_mm < training.min.diameter_mm ||
                         p.diameter_mm > training.max.diameter_mm ||
                         p.pitch_mm < training.min.pitch_mm || p.pitch_mm > training.max.pitch_mm ||
                         p.cutting_speed_m_min < training.min.cutting_speed_m_min ||
                         p.cutting_speed_m_min > training.max.cutting_speed_m_min;
    EXPECT_TRUE(outside) << s.name;
  }
}

}  // namespace
}  // namespace whirl::compare
