// family/transform.h: which columns get a log, the refusal of non-positive values, the delta
// method against finite differences and Monte Carlo, and the JSON round trip.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "family/transform.h"
#include "support/expect_error.h"

namespace whirl::family {
namespace {

namespace nn_free {
// The table's inputs as 5 x rows (nn::InputMatrix without the nn dependency).
Eigen::MatrixXd Inputs(const ProcessTable& t) {
  Eigen::MatrixXd x(5, static_cast<Eigen::Index>(t.inputs.size()));
  for (std::size_t q = 0; q < t.inputs.size(); ++q)
    for (int i = 0; i < 5; ++i) x(i, static_cast<Eigen::Index>(q)) = t.inputs[q].ToArray()[i];
  return x;
}
}  // namespace nn_free

ProcessTable Table() {
  ProcessTable t;
  t.source = "t.csv";
  for (int q = 0; q < 5; ++q) {
    t.inputs.push_back(
        ProcessInputs::FromArray({60.0 + q, 50.0 + q, 6.0 + 0.1 * q, 3.0 + q, 150.0 + q}));
    t.targets.push_back(Features::FromArray({10.0 + q, 100.0 + 5 * q}));
  }
  return t;
}

TEST(Transform, LogOnlyWhereEveryValueIsPositive) {
  ProcessTable t = Table();
  TableTransform all = LogWherePositive(t);
  for (ColumnTransform c : all.inputs) EXPECT_EQ(c, ColumnTransform::kLog);
  for (ColumnTransform c : all.outputs) EXPECT_EQ(c, ColumnTransform::kLog);
  EXPECT_EQ(all.Describe(), "log of every input and output");
  t.targets[2].max_elongation_um = 0.0;  // a zero
  t.inputs[4].pitch_mm = -1.0;           // a negative value
  const TableTransform some = LogWherePositive(t);
  EXPECT_EQ(some.outputs[0], ColumnTransform::kIdentity);
  EXPECT_EQ(some.outputs[1], ColumnTransform::kLog);
  EXPECT_EQ(some.inputs[2], ColumnTransform::kIdentity);
  EXPECT_EQ(some.inputs[3], ColumnTransform::kLog);
  EXPECT_TRUE(TableTransform{}.IsIdentity());
  EXPECT_FALSE(some.IsIdentity());
}

TEST(Transform, NonPositiveValuesOfALogColumnAreInputErrors) {
  TableTransform t = LogWherePositive(Table());
  Eigen::MatrixXd x = Eigen::MatrixXd::Constant(5, 3, 2.0);
  x(3, 1) = 0.0;
  ExpectInputError([&] { TransformInputs(t, x); }, "raceway_radius_mm = 0 (sample 2)");
  EXPECT_EQ(Forward(ColumnTransform::kIdentity, -3.0, "c"), -3.0);
  ExpectInputError([] { Forward(ColumnTransform::kLog, -3.0, "pitch_mm"); }, "pitch_mm = -3");
  EXPECT_NEAR(TransformInputs(t, Eigen::MatrixXd::Constant(5, 1, std::exp(1.5)))(0, 0), 1.5, 1e-15);
}

TEST(Transform, DeltaMethodUsesTheDerivativeOfTheInverse) {
  for (ColumnTransform c : {ColumnTransform::kIdentity, ColumnTransform::kLog})
    for (double m : {-2.0, 0.3, 4.0}) {
      const double h = 1e-6;
      const double fd = (Inverse(c, m + h) - Inverse(c, m - h)) / (2 * h);
      EXPECT_NEAR(InverseDerivative(c, m), fd, 1e-8 * std::max(1.0, std::abs(fd)));
      const MeanSd b = MapBack(c, m, 0.25);
      EXPECT_DOUBLE_EQ(b.mean, Inverse(c, m));
      EXPECT_NEAR(b.sd, 0.25 * fd, 1e-8 * std::max(1.0, std::abs(fd)));
      EXPECT_DOUBLE_EQ(Inverse(c, Forward(c, Inverse(c, m), "x")), Inverse(c, m));
    }
}

TEST(Transform, DeltaMethodAgreesWithMonteCarloForSmallSd) {
  // z ~ N(m, s^2), y = exp(z): the sample sd of y is exp(m) s (1 + O(s^2)), its median exp(m).
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n01;
  const double m = 2.0, s = 0.05;
  std::vector<double> y(200000);
  double sum = 0, sum2 = 0;
  for (double& v : y) {
    v = std::exp(m + s * n01(rng));
    sum += v;
    sum2 += v * v;
  }
  const double mean = sum / y.size(), sd = std::sqrt(sum2 / y.size() - mean * mean);
  std::nth_element(y.begin(), y.begin() + y.size() / 2, y.end());
  const MeanSd b = MapBack(ColumnTransform::kLog, m, s);
  EXPECT_NEAR(b.sd / sd, 1.0, 0.01);                  // relative error O(s^2) + sampling
  EXPECT_NEAR(b.mean / y[y.size() / 2], 1.0, 0.001);  // the median
}

TEST(Transform, AConstantInputIsLeftOut) {
  ProcessTable t = Table();
  for (ProcessInputs& p : t.inputs) p.pitch_mm = 6.0;
  const TableTransform a = LogWherePositive(t);
  EXPECT_FALSE(a.input_used[2]);
  EXPECT_EQ(a.UsedInputCount(), 4);
  EXPECT_EQ(a.Describe(), "log of every column used; left out (constant): pitch_mm");
  const Eigen::MatrixXd z = TransformInputs(a, nn_free::Inputs(t));
  EXPECT_EQ(z.row(2).cwiseAbs().maxCoeff(), 0.0);  // a left-out input is 0 in every row
  EXPECT_NEAR(z(3, 1), std::log(4.0), 1e-15);
  const Eigen::MatrixXd used = UsedInputRows(a, z);
  ASSERT_EQ(used.rows(), 4);
  EXPECT_EQ(used.row(2), z.row(3));
  TableTransform b;
  EXPECT_EQ(LeaveOutConstantInputs(t, &b), std::vector<int>{2});
  EXPECT_TRUE(b.IsIdentity());
  const TableTransform back = nlohmann::json(a).get<TableTransform>();
  EXPECT_EQ(back.input_used, a.input_used);
  EXPECT_FALSE(nlohmann::json(TableTransform{}).contains("inputs_used"));  // files stay as they were
  nlohmann::json j = a;
  j["inputs_used"] = {false, false, false, false, false};
  ExpectInputError([&] { j.get<TableTransform>(); }, "leaves out every input");
  j["inputs_used"] = {true, 1, true, true, true};
  ExpectInputError([&] { j.get<TableTransform>(); }, "'inputs_used'[1] must be true or false");
}

TEST(Transform, JsonRoundTripAndBadNames) {
  ProcessTable t = Table();
  t.inputs[0].hardness_hrc = 0.0;
  const TableTransform a = LogWherePositive(t);
  const TableTransform b = nlohmann::json(a).get<TableTransform>();
  EXPECT_EQ(a.inputs, b.inputs);
  EXPECT_EQ(a.outputs, b.outputs);
  nlohmann::json j = a;
  j["outputs"][1] = "sqrt";
  ExpectInputError([&] { j.get<TableTransform>(); }, "transform 'sqrt'");
  j["outputs"] = {"log"};
  ExpectInputError([&] { j.get<TableTransform>(); }, "'outputs' must be an array of 2");
}

}  // namespace
}  // namespace whirl::family
