// The ceiling of the machine half (machine_eval/ceiling.h): a slope planted in the machine's truth
// (constant in time, (z_ref - z) / 1000 um per um) is learned exactly by every feature set, since
// each holds a slope intercept, while the uncompensated machine half grows with it.
#include <gtest/gtest.h>

#include <cmath>

#include "core/process.h"
#include "machine/scenarios.h"
#include "machine_eval/ceiling.h"
#include "workpiece/model.h"

namespace whirl::machine_eval {
namespace {

CeilingScenario SmallCeiling(double planted_um_per_1000, bool grey_structure = false) {
  static const workpiece::WorkpieceModel model =
      workpiece::LoadWorkpieceModel(std::string(WHIRL_SOURCE_DIR) + "/models/default.json");
  static const compare::ExperienceRule rule = compare::BuildExperienceRule(
      ReadProcessTable(std::string(WHIRL_SOURCE_DIR) + "/datasets/whirling_500.csv", true));
  static const lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(
      std::string(WHIRL_SOURCE_DIR) + "/datasets/standards/iso3408_3_lead_tolerances.csv");
  CeilingOptions o;
  o.field.machines = 1;
  o.field.threads = 1;
  o.field.calendar.warmup_speeds_m_min = {180};
  o.field.calendar.past_days = 4;
  o.field.calendar.test_days = 1;
  o.estimator_past_days = 2;
  o.row_step_min = 2;
  o.grey_structure = grey_structure;
  const double z_ref = o.field.machine.z.fixed_end_mm;
  if (planted_um_per_1000 != 0)
    o.field.timeline.extra_error_um = [=](double, double z_mm) {
      return planted_um_per_1000 * (z_ref - z_mm) / 1000.0;
    };
  return EvaluateCeiling(machine::FindMachineScenario("production"), model, rule, iso, o, 1);
}

TEST(Ceiling, APlantedConstantSlopeIsLearnedByEveryFeatureSet) {
  const CeilingScenario plain = SmallCeiling(0), planted = SmallCeiling(8);
  ASSERT_EQ(plain.cuts.size(), planted.cuts.size());
  ASSERT_GE(plain.cuts.size(), 3u);
  double grown = 0;
  for (std::size_t i = 0; i < plain.cuts.size(); ++i) {
    const CeilingCut &a = plain.cuts[i], &b = planted.cuts[i];
    ASSERT_EQ(a.ceiling_um.size(), CeilingFeatureSets().size());
    for (std::size_t s = 0; s + 1 < a.ceiling_um.size(); ++s)  // +contact: NaN without a reading
      EXPECT_NEAR(b.ceiling_um[s], a.ceiling_um[s], 0.05)
          << CeilingFeatureSets()[s] << " cut " << i;
    EXPECT_TRUE(std::isnan(a.ceiling_um.back()));
    grown += b.estimator_um[0] - a.estimator_um[0];  // uncompensated
  }
  EXPECT_GT(grown / plain.cuts.size(), 5.0);  // the plant is large where nothing learns it
}

// The grey structure (grey_structure): the grey box reading the true blank column latches the
// blank's true temperature at every cut start exactly; the field grey box's estimate (a lag of
// the hall's sensor) is finite and not exact; every grey column is scored on every cut. (A
// planted constant slope is not learned exactly here: the ridge pulls g0 towards 0 with a
// strength chosen by CV, unlike the ceiling's free intercepts.)
TEST(Ceiling, TheGreyStructureLatchesTheTrueBlankExactly) {
  const CeilingScenario plain = SmallCeiling(0, true);
  ASSERT_GE(plain.cuts.size(), 3u);
  ASSERT_EQ(plain.grey_median_um.size(), CeilingGreyColumns().size());
  double estimate_off = 0;
  for (std::size_t i = 0; i < plain.cuts.size(); ++i) {
    const CeilingCut& a = plain.cuts[i];
    ASSERT_EQ(a.grey_um.size(), CeilingGreyColumns().size());
    ASSERT_EQ(a.blank_error_k.size(), CeilingBlankModels().size());
    EXPECT_NEAR(a.blank_error_k[2], 0.0, 1e-9) << "cut " << i;
    for (std::size_t m = 0; m < 2; ++m) ASSERT_TRUE(std::isfinite(a.blank_error_k[m]));
    estimate_off = std::max(estimate_off, std::abs(a.blank_error_k[1]));
    for (double g : a.grey_um) EXPECT_TRUE(std::isfinite(g) && g >= 0) << "cut " << i;
  }
  EXPECT_GT(estimate_off, 0.01);  // a lag of the hall's sensor is not the blank's truth
  // Without the option nothing of it is computed and the other columns are the same.
  const CeilingScenario off = SmallCeiling(0);
  ASSERT_EQ(off.cuts.size(), plain.cuts.size());
  EXPECT_TRUE(off.grey_median_um.empty());
  for (std::size_t i = 0; i < off.cuts.size(); ++i) {
    EXPECT_TRUE(off.cuts[i].grey_um.empty());
    EXPECT_EQ(off.cuts[i].ceiling_um.size(), plain.cuts[i].ceiling_um.size());
    for (std::size_t s = 0; s + 1 < off.cuts[i].ceiling_um.size(); ++s)
      EXPECT_EQ(off.cuts[i].ceiling_um[s], plain.cuts[i].ceiling_um[s]);
    EXPECT_EQ(off.cuts[i].estimator_um, plain.cuts[i].estimator_um);
  }
}

}  // namespace
}  // namespace whirl::machine_eval
