// The history baselines (compare/traditional.h) and the scenario disturbances
// (sim/simulator.h) against closed forms and hand-computed examples.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "compare/history_rules.h"
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

// Two 80 mm screws and one 50 mm screw, targets small enough to compute by hand.
ProcessTable HandTable() {
  ProcessTable h;
  h.source = "hand";
  h.inputs = {{62, 80, 10, 3.7, 180}, {62, 82, 10, 3.7, 180}, {62, 50, 10, 3.7, 180}};
  h.targets = {{10, 200}, {14, 300}, {20, 100}};
  return h;
}

// Hand-computed class means: two 80 mm screws and one 50 mm screw.
TEST(Baselines, TraditionalUsesTheClassMeanPlateauAndSettleTime) {
  const ProcessTable h = HandTable();
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
  const screw::Screw screw = screw::ReferenceScrew();
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
  for (const auto& s : ScenarioScrews(out, screw::ReferenceScrew(), 20, 9)) {
    const auto& p = s.process;
    const bool outside = p.diameter_mm < training.min.diameter_mm ||
                         p.diameter_mm > training.max.diameter_mm ||
                         p.pitch_mm < training.min.pitch_mm || p.pitch_mm > training.max.pitch_mm ||
                         p.cutting_speed_m_min < training.min.cutting_speed_m_min ||
                         p.cutting_speed_m_min > training.max.cutting_speed_m_min;
    EXPECT_TRUE(outside) << s.name;
  }
}


// Six hand-placed past screws: two in one cell, one in each of four others. Cells by (raceway
// radius, speed, lead) class with the default edges 4.48/6.69 mm, 167.8/187.7 m/min, 8.32/11.54 mm.
ProcessTable SixRowTable() {
  ProcessTable h;
  h.source = "six";
  h.inputs = {{62, 60, 7, 4.0, 160},    // cell (0,0,0)
              {62, 90, 8, 4.2, 155},    // cell (0,0,0)
              {62, 60, 10, 5.0, 160},   // cell (1,0,1)
              {62, 60, 14, 8.0, 200},   // cell (2,2,2)
              {62, 60, 14, 8.0, 160},   // cell (2,0,2)
              {62, 60, 7, 4.0, 200}};   // cell (0,2,0)
  h.targets = {{10, 100}, {20, 300}, {30, 400}, {40, 500}, {50, 600}, {60, 700}};
  return h;
}

TEST(HistoryRules, ExperienceTableCellMeansAndEmptyCellFallback) {
  const ExperienceTable t = BuildExperienceTable(SixRowTable());
  // The populated cell: mean of its two screws.
  EXPECT_DOUBLE_EQ(t.Predict({60, 70, 7.5, 4.1, 151}).max_elongation_um, 15);
  EXPECT_DOUBLE_EQ(t.Predict({60, 70, 7.5, 4.1, 151}).settle_time_s, 200);
  // Cell (1,0,0) is empty; its Chebyshev-1 neighbours that hold screws: (0,0,0) mean 15/200 and
  // (1,0,1) 30/400: the mean of the two cell means.
  EXPECT_DOUBLE_EQ(t.Predict({60, 70, 7.0, 5.0, 160}).max_elongation_um, 22.5);
  EXPECT_DOUBLE_EQ(t.Predict({60, 70, 7.0, 5.0, 160}).settle_time_s, 300);
  // Cell (2,1,0) is empty; distance 1: (1,0,1) only -> 30.
  EXPECT_DOUBLE_EQ(t.Predict({60, 70, 7.0, 9.0, 180}).max_elongation_um, 30);
  // A class upper edge belongs to the lower class.
  EXPECT_EQ(t.CellOf({60, 70, 8.32, 4.48, 167.8}), 0);
  EXPECT_EQ(t.CellOf({60, 70, 8.33, 4.49, 167.9}), 13);
  ProcessTable empty;
  empty.source = "empty";
  EXPECT_THROW(BuildExperienceTable(empty), InputError);
}

TEST(HistoryRules, NearestScrewsReturnsARowForKOneAndAveragesK) {
  const ProcessTable h = SixRowTable();
  const NearestScrews n = BuildNearestScrews(h);
  for (std::size_t r = 0; r < h.inputs.size(); ++r) {
    EXPECT_DOUBLE_EQ(n.Predict(h.inputs[r], 1).max_elongation_um, h.targets[r].max_elongation_um);
    EXPECT_DOUBLE_EQ(n.Predict(h.inputs[r], 1).settle_time_s, h.targets[r].settle_time_s);
  }
  // Leaving row 0 out (scaled by the ranges: diameter 30, lead 7, radius 4, speed 45), its
  // nearest is row 2 (lead 3/7, radius 1/4: squared distance 0.246) before row 5 (speed 40/45:
  // 0.790) and row 1 (diameter 30/30: > 1).
  EXPECT_DOUBLE_EQ(n.Predict(h.inputs[0], 1, 0).max_elongation_um, 30);
  EXPECT_DOUBLE_EQ(n.Predict(h.inputs[0], 2, 0).max_elongation_um, 45);
  // k larger than the history: the mean of all rows.
  EXPECT_DOUBLE_EQ(n.Predict(h.inputs[0], 50).max_elongation_um, 35);
}

// A planted history where the features depend on the table's key only (each cell's value exact,
// two or more screws per cell, diameters random): leave-one-out must choose the table, whose
// error is zero, and "traditional" must use it.
TEST(HistoryRules, LeaveOneOutChoosesTheTableWhenItIsExact) {
  ProcessTable h;
  h.source = "planted";
  Rng rng(11);
  const double radius[] = {3.5, 5.5, 8.5}, speed[] = {155, 178, 200}, lead[] = {7, 10, 14};
  for (int cell = 0; cell < 27; ++cell)
    for (int rep = 0; rep < 3; ++rep) {
      const int a = cell / 9, b = (cell / 3) % 3, c = cell % 3;
      h.inputs.push_back({60 + 5 * rng.Uniform(), 50 + 50 * rng.Uniform(), lead[c], radius[a],
                          speed[b]});
      h.targets.push_back({10.0 + 3 * a + 5 * b + 7 * c, 200.0 + 40 * a - 30 * b + 10 * c});
    }
  const ExperienceRule rule = BuildExperienceRule(h);
  ASSERT_TRUE(rule.has_choice);
  EXPECT_EQ(rule.choice.chosen, HistoryRule::kTable);
  EXPECT_NEAR(rule.choice.loo_relative_error[1], 0.0, 1e-12);
  EXPECT_GT(rule.choice.loo_relative_error[0], 0.05);
  EXPECT_GT(rule.choice.loo_relative_error[2], 0.0);
  const ProcessInputs q{61, 70, 10, 5.5, 200};
  EXPECT_DOUBLE_EQ(rule.TraditionalFeatures(q).max_elongation_um, 10 + 3 + 5 * 2 + 7);
  // The class rule's choice when the diameter alone decides.
  ProcessTable d = h;
  for (std::size_t r = 0; r < d.inputs.size(); ++r)
    d.targets[r] = {d.inputs[r].diameter_mm < 63 ? 10.0 : 30.0, 300};
  for (auto& p : d.inputs) p.diameter_mm = p.diameter_mm < 63 ? 50 : 90;
  EXPECT_EQ(BuildExperienceRule(d).choice.chosen, HistoryRule::kClass);
}

// The ramp rule's leave-one-out score by hand on three screws: two of the 80 mm class
// (10 um, 200 s; 14 um, 300 s) and one of the 50 mm class (20 um, 100 s). Without a screw the
// ramp takes its class's other screw's plateau (the 50 mm screw, alone in its class, the mean of
// the others) and the others' mean settle time as the ramp time:
//   (|14 - 10| / 10 + |200 - 200| / 200) / 2 = 0.2
//   (|10 - 14| / 14 + |150 - 300| / 300) / 2 = 11 / 28
//   (|12 - 20| / 20 + |250 - 100| / 100) / 2 = 0.95
TEST(HistoryRules, RampLeaveOneOutErrorByHand) {
  ProcessTable h = HandTable();
  const ExperienceRule rule = BuildExperienceRule(h);
  EXPECT_NEAR(rule.ramp_loo_relative_error, (0.2 + 11.0 / 28 + 0.95) / 3, 1e-12);
  EXPECT_NEAR(RampLeaveOneOutError(h, rule), rule.ramp_loo_relative_error, 0);
  h.inputs.resize(1);
  h.targets.resize(1);
  EXPECT_THROW(RampLeaveOneOutError(h, rule), InputError);
  EXPECT_TRUE(std::isnan(BuildExperienceRule(h).ramp_loo_relative_error));
}

// The regression's leave-one-out score against the closed form of least squares: the residual of
// row i in a fit without it is e_i / (1 - h_ii) (e: the full fit's residual, h: the hat matrix),
// here in the logs of both features. An exact power law scores 0; fewer than 8 rows: NaN.
TEST(Baselines, RegressionLeaveOneOutErrorMatchesTheHatMatrixClosedForm) {
  ProcessTable h;
  h.source = "noisy power law";
  Rng rng(5);
  for (int i = 0; i < 25; ++i) {
    const ProcessInputs p{60 + 5 * rng.Uniform(), 50 + 50 * rng.Uniform(), 6 + 10 * rng.Uniform(),
                          3 + 7 * rng.Uniform(), 150 + 60 * rng.Uniform()};
    h.inputs.push_back(p);
    h.targets.push_back({0.3 * p.diameter_mm * std::exp(0.1 * rng.Normal()),
                         9e5 / p.cutting_speed_m_min * std::exp(0.2 * rng.Normal())});
  }
  const int n = static_cast<int>(h.inputs.size()), p = ProcessInputs::kCount + 1;
  Eigen::MatrixXd a(n, p), y(n, 2);
  for (int r = 0; r < n; ++r) {
    const auto x = h.inputs[r].ToArray();
    a(r, 0) = 1;
    for (int i = 0; i < ProcessInputs::kCount; ++i) a(r, i + 1) = std::log(x[i]);
    y(r, 0) = std::log(h.targets[r].max_elongation_um);
    y(r, 1) = std::log(h.targets[r].settle_time_s);
  }
  const Eigen::MatrixXd hat = a * (a.transpose() * a).inverse() * a.transpose();
  const Eigen::MatrixXd e = y - hat * y;
  double expected = 0;
  for (int r = 0; r < n; ++r) {
    const double lp = y(r, 0) - e(r, 0) / (1 - hat(r, r)), lt = y(r, 1) - e(r, 1) / (1 - hat(r, r));
    expected += 0.5 * (std::abs(std::exp(lp) - h.targets[r].max_elongation_um) /
                           h.targets[r].max_elongation_um +
                       std::abs(std::exp(lt) - h.targets[r].settle_time_s) /
                           h.targets[r].settle_time_s) /
                n;
  }
  EXPECT_GT(expected, 0.02);
  EXPECT_NEAR(RegressionLeaveOneOutError(h), expected, 1e-9);
  EXPECT_NEAR(BuildExperienceRule(h).regression_loo_relative_error, expected, 1e-9);
  for (std::size_t r = 0; r < h.inputs.size(); ++r)  // the same inputs, exact power-law targets
    h.targets[r] = {0.3 * h.inputs[r].diameter_mm, 9e5 / h.inputs[r].cutting_speed_m_min};
  EXPECT_NEAR(RegressionLeaveOneOutError(h), 0.0, 1e-9);
  h.inputs.resize(7);
  h.targets.resize(7);
  EXPECT_TRUE(std::isnan(RegressionLeaveOneOutError(h)));
  const ExperienceRule seven = BuildExperienceRule(h);
  EXPECT_TRUE(seven.has_regression);  // 7 rows fit 6 coefficients, but leave none to spare
  EXPECT_TRUE(std::isnan(seven.regression_loo_relative_error));
}

}  // namespace
}  // namespace whirl::compare
