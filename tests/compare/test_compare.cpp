// The strategy comparison: properties through the 840D plan, and a smoke test on the
// reference screw with the shipped model (skipped, with a message, if the model is not shipped).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "compare/compare.h"
#include "compare/evaluate.h"
#include "compare/report.h"
#include "core/error.h"
#include "support/scratch_dir.h"
#include "support/source_dir.h"

namespace whirl::compare {
namespace {

using test::kSource;

ElongationCurve Sampled(const fit::ArctanCurve& curve, double duration_s, double step_s) {
  ElongationCurve c;
  for (double t = 0; t <= duration_s + 1e-9; t += step_s) {
    c.time_s.push_back(t);
    c.elongation_um.push_back(curve.ElongationUm(t));
  }
  return c;
}

CompensationFunction PlanCompensation(const interp::CompensationPlan& plan, double feed) {
  return [&plan, feed](double t) {
    return interp::AppliedCompensationUm(plan, interp::AxisPositionMm(plan.options, feed, t));
  };
}

TEST(ComparePlan, ZeroElongationTruthAndZeroPredictionGiveZeroDeviation) {
  const double feed = 0.667, length = 5100;
  fit::ArctanCurve zero;
  zero.max_elongation_um = 0;
  zero.settle_time_s = 250;
  const interp::CompensationPlan plan = interp::BuildPlan(zero, feed, length, {});
  const ElongationCurve truth = Sampled(zero, length / feed + 1, 1.0);
  const lead::LeadDeviation d = CutLeadDeviation(truth, PlanCompensation(plan, feed), feed, length, 10);
  for (double v : d.deviation_um) ASSERT_NEAR(v, 0.0, 1e-12);
}

TEST(ComparePlan, PlanOfTheTruthLeavesOnlyThePlanTolerance) {
  // Truth = the arctan curve itself, for either sign convention and direction: the lead error left
  // is the chord error of the plan, bounded by its tolerance (twice: d is a difference of two
  // residuals), far below the uncompensated error.
  for (auto control : {interp::ControlDk::kAdded, interp::ControlDk::kSubtracted})
    for (int direction : {1, -1}) {
      const interp::SignConvention sign = interp::ExpectedSign(direction, control);
      fit::ArctanCurve curve;
      curve.max_elongation_um = 40;
      curve.settle_time_s = 300;
      curve.shape_k = 4;
      interp::PlanOptions po;
      po.sign = sign;
      po.control_dk = control;
      po.direction = direction;
      po.start_position_mm = 100;
      po.tolerance_um = 0.5;
      const double feed = 0.667, length = 5100;
      const interp::CompensationPlan plan = interp::BuildPlan(curve, feed, length, po);
      const ElongationCurve truth = Sampled(curve, length / feed + 1, 0.25);
      const lead::LeadDeviation d =
          CutLeadDeviation(truth, PlanCompensation(plan, feed), feed, length, 10);
      const lead::LeadDeviation none = CutLeadDeviation(truth, NoCompensation(), feed, length, 10);
      const lead::LeadMetrics m = lead::ComputeLeadMetrics(d), n = lead::ComputeLeadMetrics(none);
      EXPECT_LE(m.accumulated_total_um, 2 * po.tolerance_um + 0.05)
          << "sign " << interp::ToString(sign) << " direction " << direction;
      EXPECT_NEAR(n.accumulated_total_um, 40.0, 1e-6);
    }
}

TEST(Compare, ReductionsFollowTheirFormula) {
  lead::LeadMetrics a, b;
  a.accumulated_1000_um = 3;
  b.accumulated_1000_um = 12;
  a.e_a_um = -2;
  b.e_a_um = 4;
  b.v_u_um = 0;
  const MetricReductions r = Reductions(a, b);
  EXPECT_DOUBLE_EQ(*r.accumulated_1000_pct, 75.0);
  EXPECT_DOUBLE_EQ(*r.e_a_pct, 50.0);
  EXPECT_FALSE(r.v_u_pct.has_value());
  EXPECT_DOUBLE_EQ(Stats({5, 1, 3, 2}).median_pct, 2.5);
  EXPECT_DOUBLE_EQ(Stats({5, 1, 3}).median_pct, 3);
  EXPECT_DOUBLE_EQ(Stats({5, 1, 3}).worst_pct, 1);
}

// A larger error than the baseline's reads "more than", never "-5 % less than".
TEST(Compare, ReductionWordsSayLessOrMore) {
  lead::LeadMetrics model, traditional;
  model.accumulated_1000_um = 10.5;
  traditional.accumulated_1000_um = 10;
  const double pct = *Reductions(model, traditional).accumulated_1000_pct;  // -5
  EXPECT_EQ(ReductionWords(pct, 0), "5 % more than");
  EXPECT_EQ(ReductionWords(75, 1), "75.0 % less than");
  EXPECT_EQ(ReductionWords(0, 0), "0 % less than");
}

TEST(Compare, RandomScrewsAreFeasibleInRangeAndReproducible) {
  const auto a = RandomFeasibleScrews(screw::ReferenceScrew(), 30, 9);
  const auto b = RandomFeasibleScrews(screw::ReferenceScrew(), 30, 9);
  ASSERT_EQ(a.size(), 30u);
  const InputRanges r;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NO_THROW(screw::ValidateScrew(a[i]));
    const auto x = a[i].process.ToArray(), lo = r.min.ToArray(), hi = r.max.ToArray();
    for (int k = 0; k < ProcessInputs::kCount; ++k) {
      EXPECT_GE(x[k], lo[k]);
      EXPECT_LE(x[k], hi[k]);
    }
    EXPECT_EQ(a[i].process.diameter_mm, b[i].process.diameter_mm);
  }
  EXPECT_NO_THROW(screw::ValidateScrew(NewTypeScrew(screw::ReferenceScrew())));
}

class ShippedModel : public ::testing::Test {
 protected:
  void SetUp() override {
    model_path_ = kSource / "models/default.json";
    history_path_ = kSource / "datasets/whirling_train.csv";
    ASSERT_TRUE(std::filesystem::exists(model_path_)) << model_path_ << " not shipped";
    ASSERT_TRUE(std::filesystem::exists(history_path_)) << history_path_ << " not shipped";
  }
  std::filesystem::path model_path_, history_path_;
};

TEST_F(ShippedModel, ReferenceScrewComparisonIsConsistent) {
  const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(model_path_);
  const ExperienceRule rule = BuildExperienceRule(ReadProcessTable(history_path_, true));
  const lead::IsoToleranceTable iso =
      lead::ReadIsoToleranceTable(kSource / "datasets/standards/iso3408_3_lead_tolerances.csv");
  CompareOptions options;
  options.seed = 3;
  const ScrewComparison c = CompareScrew(screw::ReferenceScrew(), model, rule, iso, options);
  const auto& none = c.Outcome(Strategy::kNone);
  const auto& model_o = c.Outcome(Strategy::kModel);
  // The uncompensated lead error equals the truth's elongation change along the cut.
  double lo = 1e300, hi = -1e300;
  for (double e : c.truth.elongation_um) {
    lo = std::min(lo, e);
    hi = std::max(hi, e);
  }
  EXPECT_NEAR(none.metrics.accumulated_total_um, hi - lo, 0.02 * (hi - lo) + 1e-6);
  // Any compensation of the right sign helps on the reference screw.
  EXPECT_LT(model_o.metrics.accumulated_1000_um, none.metrics.accumulated_1000_um);
  // Reductions are the formula applied to the metrics.
  EXPECT_NEAR(*c.model_vs_none.accumulated_1000_pct,
              100 * (1 - model_o.metrics.accumulated_1000_um / none.metrics.accumulated_1000_um),
              1e-9);
  // The applied plan compensation stays within the plan tolerance of the predicted curve.
  for (std::size_t i = 0; i < c.truth.size(); ++i)
    ASSERT_NEAR(c.compensation_um[static_cast<std::size_t>(Strategy::kModel)][i],
                c.predicted_curve.ElongationUm(c.truth.time_s[i]),
                c.plan.options.tolerance_um + 1e-6)
        << "t = " << c.truth.time_s[i];
  // Every strategy's lead starts at 0 and covers the thread.
  for (const auto& o : c.outcomes) {
    EXPECT_EQ(o.lead.deviation_um.front(), 0.0);
    EXPECT_DOUBLE_EQ(o.lead.position_mm.back(), c.screw.thread_length_mm);
  }
  // The report writes its files (plots skipped here to keep the test free of gnuplot).
  const auto dir = whirl::test::ScratchDir() / "whirl_compare_report";
  std::filesystem::remove_all(dir);
  ReportOptions ro;
  ro.plots = false;
  const ReportResult r = WriteReport(dir, {c}, ro);
  EXPECT_TRUE(std::filesystem::exists(dir / "index.html"));
  EXPECT_TRUE(std::filesystem::exists(dir / "report.json"));
  EXPECT_TRUE(std::filesystem::exists(dir / (Slug(c.screw.name) + "_lead.csv")));
  EXPECT_FALSE(r.plots_rendered);
}

}  // namespace
}  // namespace whirl::compare
