// family/linear.h: least squares against the normal equations, its closed-form leave-one-out
// against refits without each row, the latent variance against its formula, and the JSON round
// trip.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cstdlib>

#include "family/linear.h"
#include "support/eigen_near.h"
#include "support/expect_error.h"

namespace whirl::family {
namespace {

struct Data {
  Eigen::MatrixXd x;
  Eigen::VectorXd y;
};

Data Make(int d, int n, unsigned seed) {
  std::srand(seed);
  Data data{Eigen::MatrixXd::Random(d, n) * 5.0, Eigen::VectorXd::Zero(n)};
  data.x.row(0).array() += 40.0;  // an offset the standardization must absorb
  data.y = 3.0 + (data.x.transpose() * Eigen::VectorXd::LinSpaced(d, -1, 2)).array() +
           0.3 * Eigen::ArrayXd::Random(n);
  return data;
}

TEST(Linear, MatchesTheNormalEquationsOnRawInputs) {
  const Data data = Make(4, 15, 1);
  const LinearModel m = FitLinear(data.x, data.y);
  Eigen::MatrixXd a(15, 5);
  a << Eigen::VectorXd::Ones(15), data.x.transpose();
  const Eigen::VectorXd c = (a.transpose() * a).inverse() * a.transpose() * data.y;
  EXPECT_TRUE(test::AllNear(PredictLinear(m, data.x).mean, a * c, 1e-10, 1e-10));
  const double s2 = (data.y - a * c).squaredNorm() / (15 - 5);
  EXPECT_NEAR(m.fitted_noise_variance, s2, 1e-10 * s2);
  // latent variance s^2 a*' (A'A)^-1 a* at new points, raw design
  const Data fresh = Make(4, 3, 2);
  Eigen::MatrixXd af(3, 5);
  af << Eigen::VectorXd::Ones(3), fresh.x.transpose();
  const Eigen::VectorXd v =
      s2 * (af * (a.transpose() * a).inverse()).cwiseProduct(af).rowwise().sum();
  EXPECT_TRUE(test::AllNear(PredictLinear(m, fresh.x).latent_variance, v, 1e-8));
}

TEST(Linear, LeaveOneOutEqualsRefitsWithoutEachRow) {
  const Data data = Make(3, 12, 3);
  const LinearModel m = FitLinear(data.x, data.y);
  const LinearLeaveOneOut loo = LeaveOneOutLinear(m, data.x, data.y);
  for (int i = 0; i < 12; ++i) {
    Eigen::MatrixXd x(3, 11);
    Eigen::VectorXd y(11);
    for (int q = 0, c = 0; q < 12; ++q)
      if (q != i) {
        x.col(c) = data.x.col(q);
        y(c++) = data.y(q);
      }
    const LinearModel without = FitLinear(x, y);
    const LinearPrediction p = PredictLinear(without, data.x.col(i));
    EXPECT_NEAR(loo.residual(i), data.y(i) - p.mean(0), 1e-9);
    // the closed form keeps the full-data s^2: compare the leverage part only
    EXPECT_NEAR(loo.latent_variance(i) / m.fitted_noise_variance,
                p.latent_variance(0) / without.fitted_noise_variance, 1e-9);
  }
}

TEST(Linear, JsonRoundTripAndBadInput) {
  const Data data = Make(5, 20, 4);
  LinearModel m = FitLinear(data.x, data.y);
  m.noise_variance = 2.5;
  const LinearModel back = nlohmann::json::parse(nlohmann::json(m).dump()).get<LinearModel>();
  const LinearPrediction a = PredictLinear(m, data.x), b = PredictLinear(back, data.x);
  EXPECT_TRUE(test::AllNear(a.mean, b.mean, 1e-14));
  EXPECT_TRUE(test::AllNear(a.latent_variance, b.latent_variance, 1e-14));
  EXPECT_EQ(back.noise_variance, 2.5);
  ExpectInputError([&] { FitLinear(data.x.leftCols(7), data.y.head(7)); }, "needs at least 8");
  nlohmann::json j = m;
  j["coef"].push_back(1.0);
  ExpectInputError([&] { j.get<LinearModel>(); }, "'coef' (inputs + 1)");
}

}  // namespace
}  // namespace whirl::family
