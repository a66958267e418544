// The lead deviation of a cut (compare/cut.h) and the traditional experience rule.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "compare/cut.h"
#include "lead/metrics.h"
#include "compare/traditional.h"
#include "core/error.h"

namespace whirl::compare {
namespace {

ElongationCurve Curve(double duration_s, double step_s, const std::function<double(double)>& e) {
  ElongationCurve c;
  for (double t = 0; t <= duration_s + 1e-9; t += step_s) {
    c.time_s.push_back(t);
    c.elongation_um.push_back(e(t));
  }
  return c;
}

TEST(Cut, ZeroElongationAndNoCompensationGiveZeroDeviation) {
  const double feed = 1.1, length = 5100;
  const ElongationCurve zero = Curve(length / feed + 1, 0.5, [](double) { return 0.0; });
  const lead::LeadDeviation d = CutLeadDeviation(zero, NoCompensation(), feed, length, 10);
  EXPECT_EQ(d.position_mm.front(), 0.0);
  EXPECT_EQ(d.position_mm.back(), length);
  for (double v : d.deviation_um) EXPECT_EQ(v, 0.0);
}

TEST(Cut, CompensationEqualToTheTruthGivesZeroDeviation) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const double feed = 0.3 + 2 * u(rng), length = 500 + 5000 * u(rng);
    const double plateau = 20 + 200 * u(rng), tau = 30 + 200 * u(rng);
    auto e = [&](double t) { return plateau * (1 - std::exp(-t / tau)); };
    const ElongationCurve truth = Curve(length / feed + 2, 0.25, e);
    // The compensation follows the truth's own samples (the same linear interpolation).
    auto c = [&](double t) { return InterpolateLinear(truth.time_s, truth.elongation_um, t); };
    const lead::LeadDeviation d = CutLeadDeviation(truth, c, feed, length, 10);
    for (double v : d.deviation_um) ASSERT_NEAR(v, 0.0, 1e-9);
    // A constant compensation changes nothing against none.
    const lead::LeadDeviation none = CutLeadDeviation(truth, NoCompensation(), feed, length, 10);
    const lead::LeadDeviation offset = CutLeadDeviation(
        truth, [](double) { return 37.0; }, feed, length, 10);
    for (std::size_t i = 0; i < none.size(); ++i)
      ASSERT_NEAR(none.deviation_um[i], offset.deviation_um[i], 1e-9);
  }
}

TEST(Cut, LinearGrowthGivesALinearLeadErrorWithEaEqualToTheGrowth) {
  // e(t) = g t: d(x) = g x / v, so e_a = g * l / v and the band widths vanish.
  const double feed = 0.8, length = 2000, g = 0.05;
  const ElongationCurve truth = Curve(length / feed, 1.0, [&](double t) { return g * t; });
  const lead::LeadDeviation d = CutLeadDeviation(truth, NoCompensation(), feed, length, 10);
  for (std::size_t i = 0; i < d.size(); ++i)
    ASSERT_NEAR(d.deviation_um[i], g * d.position_mm[i] / feed, 1e-9);
  lead::LeadMetricOptions options;
  options.lead_mm = 10;
  const lead::LeadMetrics m = lead::ComputeLeadMetrics(d, options);
  EXPECT_NEAR(m.e_a_um, g * length / feed, 1e-6);
  EXPECT_NEAR(m.v_u_um, 0, 1e-6);
  EXPECT_NEAR(m.accumulated_1000_um, g * 1000 / feed, 1e-6);
}

TEST(Cut, SampleStepResolvesOneLead) {
  const ElongationCurve truth = Curve(1000, 1.0, [](double t) { return std::sqrt(t); });
  const lead::LeadDeviation d = CutLeadDeviation(truth, NoCompensation(), 1.0, 1000, 6);
  for (std::size_t i = 1; i < d.size(); ++i)
    ASSERT_LE(d.position_mm[i] - d.position_mm[i - 1], 0.6 + 1e-12);
}

TEST(Cut, RejectsBadInput) {
  const ElongationCurve truth = Curve(100, 1.0, [](double t) { return t; });
  EXPECT_THROW(CutLeadDeviation(truth, NoCompensation(), 0.0, 100, 10), InputError);
  EXPECT_THROW(CutLeadDeviation(truth, NoCompensation(), 1.0, -1, 10), InputError);
  EXPECT_THROW(CutLeadDeviation(truth, NoCompensation(), 1.0, 100, 0), InputError);
  // The truth stops at 100 s but the cut lasts 200 s.
  try {
    CutLeadDeviation(truth, NoCompensation(), 1.0, 200, 10);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("before the cut ends"), std::string::npos) << e.what();
  }
  CutOptions bad;
  bad.sample_step_mm = -1;
  EXPECT_THROW(CutLeadDeviation(truth, NoCompensation(), 1.0, 100, 10, bad), InputError);
}

ProcessTable History() {
  // Diameters in three of the four classes (50 | 56.1 | 63 | 71.0 | 80 | 89.4 | 100).
  ProcessTable t;
  t.source = "history";
  const double dia[] = {50, 55, 80, 85, 100};
  const double plateau[] = {60, 80, 100, 140, 200};
  const double settle[] = {200, 220, 240, 260, 280};
  for (int i = 0; i < 5; ++i) {
    ProcessInputs in;
    in.diameter_mm = dia[i];
    t.inputs.push_back(in);
    t.targets.push_back({plateau[i], settle[i]});
  }
  return t;
}

TEST(ExperienceRule, ClassMeansAndMachineRampFromTheHistory) {
  const ExperienceRule rule = BuildExperienceRule(History());
  ASSERT_EQ(rule.classes.size(), 4u);
  EXPECT_DOUBLE_EQ(rule.ramp_time_s, 240.0);
  EXPECT_DOUBLE_EQ(rule.machine_plateau_um, 116.0);
  EXPECT_DOUBLE_EQ(rule.ClassFor(52).plateau_um, 70.0);
  EXPECT_EQ(rule.ClassFor(52).screws, 2);
  EXPECT_DOUBLE_EQ(rule.ClassFor(65).plateau_um, 116.0);  // empty class: machine mean
  EXPECT_EQ(rule.ClassFor(65).screws, 0);
  EXPECT_DOUBLE_EQ(rule.ClassFor(80).plateau_um, 120.0);
  EXPECT_DOUBLE_EQ(rule.ClassFor(95).plateau_um, 200.0);
  EXPECT_NEAR(rule.ClassFor(89.0).nominal_diameter_mm, 80, 0);
  EXPECT_NEAR(rule.ClassFor(90.0).nominal_diameter_mm, 100, 0);
  // The ramp: 0 at the start, linear, the class plateau from T on.
  EXPECT_EQ(rule.CompensationUm(80, 0), 0.0);
  EXPECT_DOUBLE_EQ(rule.CompensationUm(80, 60), 120.0 * 60 / 240);
  EXPECT_DOUBLE_EQ(rule.CompensationUm(80, 240), 120.0);
  EXPECT_DOUBLE_EQ(rule.CompensationUm(80, 5000), 120.0);
}

TEST(ExperienceRule, RejectsAHistoryWithoutTargetsOrBadClasses) {
  ProcessTable no_targets = History();
  no_targets.targets.clear();
  EXPECT_THROW(BuildExperienceRule(no_targets), InputError);
  EXPECT_THROW(BuildExperienceRule(ProcessTable{}), InputError);
  ExperienceRuleOptions bad;
  bad.class_diameters_mm = {50, 40};
  EXPECT_THROW(BuildExperienceRule(History(), bad), InputError);
}

TEST(ExperienceRule, ZeroElongationHistoryAndTruthGiveZeroDeviation) {
  ProcessTable cold = History();
  for (auto& f : cold.targets) f.max_elongation_um = 0;
  const ExperienceRule rule = BuildExperienceRule(cold);
  const ElongationCurve zero = Curve(6000, 1.0, [](double) { return 0.0; });
  const lead::LeadDeviation d = CutLeadDeviation(
      zero, [&](double t) { return rule.CompensationUm(80, t); }, 1.0, 5100, 10);
  for (double v : d.deviation_um) EXPECT_EQ(v, 0.0);
}

}  // namespace
}  // namespace whirl::compare
