// family/family.h and family/transform.h on small and odd tables: 8- and 9-row tables train and
// count the table's rows in their errors, a constant input is named and left out, a zero or
// near-zero target keeps its column raw with a warning and an honest name, and the same table
// and seed give the same model file byte for byte.
#include <gtest/gtest.h>

#include <cmath>

#include "family/family.h"
#include "family/transform.h"
#include "nn/model.h"
#include "support/expect_error.h"
#include "support/power_law_table.h"

namespace whirl::family {
namespace {

using test::MakeTable;

bool AllFinite(const std::vector<FamilyPrediction>& p) {
  for (const FamilyPrediction& f : p)
    for (int k = 0; k < 2; ++k)
      if (!std::isfinite(f.mean.ToArray()[k]) || !(f.stddev.ToArray()[k] > 0)) return false;
  return true;
}

TEST(SmallTables, EightAndNineRowsTrainWithLeaveOneOutCalibration) {
  const ProcessTable test = MakeTable(50, 0.0, 99);
  for (int rows : {8, 9})
    for (unsigned seed = 1; seed <= 5; ++seed) {
      const ProcessTable t = MakeTable(rows, 0.04, seed);
      const Choice c = ChooseFamily(t, {});
      EXPECT_TRUE(AllFinite(PredictChoice(c, test.inputs))) << rows << " rows, seed " << seed;
      for (const FamilyModel& m : c.models) {
        if (m.candidate.family != Family::kLinear) continue;  // 5 folds: 6 or 7 rows per fit
        EXPECT_NE(m.calibration.find("closed-form leave-one-out residuals"), std::string::npos)
            << m.calibration;
      }
      for (const char* name : {"linear/log", "linear/identity"}) {  // --family linear
        ChoiceOptions o;
        o.candidates = {ParseCandidate(name)};
        EXPECT_TRUE(AllFinite(PredictChoice(ChooseFamily(t, o), test.inputs))) << name;
      }
    }
}

TEST(SmallTables, ErrorsCountTheTablesRows) {
  const ProcessTable t = MakeTable(7, 0.04, 1);
  ExpectInputError([&] { ChooseFamily(t, {}); }, "generated.csv: 7 training rows; linear/log needs at least 8");
  ExpectInputError([&] { FitCandidate(t, ParseCandidate("linear/identity"), {}); },
                   "7 training rows; linear/identity needs at least 8");
  EXPECT_EQ(MinimumRows(ParseCandidate("linear/log"), 5), 8);
  EXPECT_EQ(MinimumRows(ParseCandidate("linear/log"), 4), 7);
  EXPECT_EQ(MinimumRows(ParseCandidate("gp-se-constant/log"), 5), 3);
  EXPECT_EQ(MinimumRows(ParseCandidate("gp-se-linear/log"), 5), 8);
}

// hardness_hrc constant: it is named in a warning, left out of every model (the fits see 4
// inputs), and the predictions do not depend on it.
TEST(ConstantInputs, AreNamedAndLeftOut) {
  ProcessTable t = MakeTable(30, 0.04, 3, true);
  for (ProcessInputs& p : t.inputs) p.hardness_hrc = 61;
  ChoiceOptions o;
  o.candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-matern52-constant/identity"),
                  ParseCandidate("network-h4/identity")};
  o.per_output = false;
  for (const Candidate& c : o.candidates) {
    const FamilyModel m = FitCandidate(t, c, o.fit);
    EXPECT_FALSE(m.transform.input_used[0]) << c.Name();
    EXPECT_EQ(m.transform.UsedInputCount(), 4);
    if (c.family == Family::kLinear) {
      EXPECT_EQ(m.linears[0].input_shift.size(), 4);
    }
    if (c.family == Family::kGaussianProcess) {
      EXPECT_EQ(m.gps[1].input_shift.size(), 4);
    }
    std::vector<ProcessInputs> a = {t.inputs[0]}, b = a;
    b[0].hardness_hrc = 45;
    const FamilyPrediction pa = PredictFamily(m, a).front(), pb = PredictFamily(m, b).front();
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(pa.mean.ToArray()[k], pb.mean.ToArray()[k]) << c.Name();
      EXPECT_EQ(pa.stddev.ToArray()[k], pb.stddev.ToArray()[k]) << c.Name();
    }
    const FamilyModel back = nlohmann::json(m).get<FamilyModel>();
    EXPECT_EQ(PredictFamily(back, b).front().mean.settle_time_s, pb.mean.settle_time_s);
  }
  const Choice c = ChooseFamily(t, o);
  ASSERT_FALSE(c.warnings.empty());
  EXPECT_EQ(c.warnings[0].rfind("hardness_hrc is constant (61 HRC in every row of generated.csv): "
                                "left out of the model",
                                0),
            0u)
      << c.warnings[0];
  const ProcessTable varied = MakeTable(30, 0.04, 3, true);
  EXPECT_TRUE(ChooseFamily(varied, o).warnings.empty());
}

// A target that is the same in every row (a clipped or rounded measurement): named in a warning,
// left out of the score (over its zero variance any candidate's MSE was a number beyond the
// model file's range, and the file was refused), and the model predicts that value.
TEST(ConstantTargets, AreNamedLeftOutOfTheScoreAndPredicted) {
  ProcessTable t = MakeTable(20, 0.04, 5);
  for (Features& f : t.targets) f.settle_time_s = 50;
  EXPECT_EQ(ConstantTargets(t), std::vector<int>{1});
  EXPECT_TRUE(ConstantTargets(MakeTable(20, 0.04, 5)).empty());
  const Choice c = ChooseFamily(t, ChoiceOptions{});
  const Eigen::MatrixXd x = nn::TargetMatrix(t.targets);
  const double var0 = (x.row(0).array() - x.row(0).mean()).square().mean();
  for (const CvRow& r : c.table)  // the score is the elongation's MSE / variance alone
    EXPECT_NEAR(r.score, r.cv_rmse(0) * r.cv_rmse(0) / var0, 1e-9 * (1 + r.score)) << r.candidate.Name();
  bool named = false;
  for (const std::string& w : c.warnings)
    named |= w.rfind("settle_time_s is the same (50 s) in every row of generated.csv", 0) == 0;
  EXPECT_TRUE(named) << ::testing::PrintToString(c.warnings);
  Choice back;
  ASSERT_NO_THROW(back = nlohmann::json(c).get<Choice>());  // the model file's range checks
  for (const FamilyPrediction& q : PredictChoice(back, MakeTable(10, 0.0, 77).inputs))
    EXPECT_NEAR(q.mean.settle_time_s, 50.0, 1e-6) << "a constant target predicted elsewhere";
}

// A 0 in max_elongation_um: the log candidates keep that output raw, say so in a warning and in
// their name for that output; settle time stays on a log scale. A near-zero value (below 1/1000
// of the median) is treated the same way; a small value above that is not.
TEST(LogExceptions, ZeroAndNearZeroTargetsKeepTheirColumnRaw) {
  for (const double bad : {0.0, 1e-3}) {
    ProcessTable t = MakeTable(20, 0.02, 4);
    t.targets[6].max_elongation_um = bad;
    const std::vector<LogException> e = LogExceptions(t);
    ASSERT_EQ(e.size(), 1u);
    EXPECT_FALSE(e[0].input);
    EXPECT_EQ(e[0].column, 0);
    EXPECT_EQ(e[0].row, 6);
    const TableTransform tr = LogWherePositive(t);
    EXPECT_EQ(tr.outputs[0], ColumnTransform::kIdentity);
    EXPECT_EQ(tr.outputs[1], ColumnTransform::kLog);
    ChoiceOptions o;
    o.candidates = {ParseCandidate("linear/log")};
    const Choice c = ChooseFamily(t, o);
    EXPECT_EQ(c.Describe(), "max_elongation_um: linear/log-inputs, settle_time_s: linear/log");
    ASSERT_EQ(c.warnings.size(), 1u);
    const std::string w = c.warnings[0];
    EXPECT_EQ(w.rfind("max_elongation_um = " + std::string(bad == 0 ? "0" : "0.001") +
                          " um (generated.csv row 7): ",
                      0),
              0u)
        << w;
    EXPECT_NE(w.find("keep max_elongation_um on its raw scale"), std::string::npos) << w;
    EXPECT_NE(w.find(bad == 0 ? "needs values > 0" : "below 0.001 of the column's median"),
              std::string::npos)
        << w;
  }
  ProcessTable t = MakeTable(20, 0.02, 4);
  t.targets[6].max_elongation_um *= 0.01;  // small, but a log of it does not dominate
  EXPECT_TRUE(LogExceptions(t).empty());
  EXPECT_EQ(LogWherePositive(t).outputs[0], ColumnTransform::kLog);
}

// Same table, same seed: the same file text, whatever the thread count (no timings stored).
TEST(Reproducible, SameTableAndSeedGiveTheSameJson) {
  const ProcessTable t = MakeTable(24, 0.05, 8, true);
  ChoiceOptions o;
  o.candidates.push_back(ParseCandidate("network-h4/log"));
  const std::string a = nlohmann::json(ChooseFamily(t, o)).dump();
  o.fit.threads = 2;
  const std::string b = nlohmann::json(ChooseFamily(t, o)).dump();
  EXPECT_EQ(a, b);
  EXPECT_EQ(a.find("fit_ms"), std::string::npos);
}

}  // namespace
}  // namespace whirl::family
