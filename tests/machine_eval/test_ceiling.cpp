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

CeilingScenario SmallCeiling(double planted_um_per_1000) {
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

}  // namespace
}  // namespace whirl::machine_eval
