// LM solver against closed forms and known optima, from poor starting points.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>

#include "core/error.h"
#include "fit/levenberg_marquardt.h"
#include "support/eigen_near.h"

namespace whirl::fit {
namespace {

TEST(LevenbergMarquardt, LinearLeastSquaresMatchesNormalEquations) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int m = 30, n = 4;
    Eigen::MatrixXd a(m, n);
    Eigen::VectorXd b(m);
    for (int i = 0; i < m; ++i) {
      for (int j = 0; j < n; ++j) a(i, j) = normal(rng);
      b[i] = normal(rng);
    }
    const Eigen::VectorXd closed = (a.transpose() * a).ldlt().solve(a.transpose() * b);
    auto residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
      *r = a * x - b;
      if (jac != nullptr) *jac = a;
    };
    Eigen::VectorXd x = Eigen::VectorXd::Constant(n, 100.0);  // far from the optimum
    const LmSummary s = SolveLeastSquares(residual, m, true, &x);
    EXPECT_TRUE(s.Converged()) << s.BriefReport();
    EXPECT_TRUE(test::AllNear(x, closed, 1e-8, 1e-9)) << s.BriefReport();
    EXPECT_NEAR(s.final_cost, 0.5 * (a * closed - b).squaredNorm(), 1e-9);
    EXPECT_GT(s.initial_cost, s.final_cost);
  }
}

// Rosenbrock as least squares: r = (10 (x2 - x1^2), 1 - x1); minimum (1, 1), cost 0.
void Rosenbrock(const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
  (*r)[0] = 10.0 * (x[1] - x[0] * x[0]);
  (*r)[1] = 1.0 - x[0];
  if (jac != nullptr) {
    (*jac)(0, 0) = -20.0 * x[0];
    (*jac)(0, 1) = 10.0;
    (*jac)(1, 0) = -1.0;
    (*jac)(1, 1) = 0.0;
  }
}

TEST(LevenbergMarquardt, RosenbrockFromPoorStarts) {
  const double starts[][2] = {{-1.2, 1.0}, {-3.0, -4.0}, {5.0, 30.0}, {0.0, -10.0}, {-10, 10}};
  for (const auto& s0 : starts) {
    for (bool analytic : {true, false}) {
      Eigen::VectorXd x(2);
      x << s0[0], s0[1];
      LmOptions o;
      o.max_iterations = 500;
      const LmSummary s = SolveLeastSquares(Rosenbrock, 2, analytic, &x, o);
      EXPECT_TRUE(s.Converged()) << s.BriefReport();
      EXPECT_NEAR(x[0], 1.0, 1e-6) << "start " << s0[0] << "," << s0[1] << " " << s.BriefReport();
      EXPECT_NEAR(x[1], 1.0, 1e-6);
      EXPECT_LT(s.final_cost, 1e-14);
    }
  }
}

TEST(LevenbergMarquardt, ExponentialDecayRecoversKnownParameters) {
  // y = a exp(-b t) + c sampled without noise: the optimum is the generating parameters.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ua(1.0, 10.0), ub(0.1, 2.0), uc(-2.0, 2.0);
  for (int trial = 0; trial < 25; ++trial) {
    const double a = ua(rng), b = ub(rng), c = uc(rng);
    const int m = 40;
    Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(m, 0.0, 8.0 / b);
    auto residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
      for (int i = 0; i < m; ++i) {
        const double e = std::exp(-x[1] * t[i]);
        (*r)[i] = x[0] * e + x[2] - (a * std::exp(-b * t[i]) + c);
        if (jac != nullptr) {
          (*jac)(i, 0) = e;
          (*jac)(i, 1) = -x[0] * t[i] * e;
          (*jac)(i, 2) = 1.0;
        }
      }
    };
    Eigen::VectorXd x(3);
    x << 1.0, 5.0 * b, 0.0;  // decay rate five times too fast, amplitude and offset wrong
    LmOptions o;
    o.max_iterations = 1000;
    o.lower_bounds = Eigen::Vector3d(-1e9, 1e-6, -1e9);  // keeps the rate positive
    const LmSummary s = SolveLeastSquares(residual, m, trial % 2 == 0, &x, o);
    EXPECT_TRUE(s.Converged()) << s.BriefReport();
    EXPECT_NEAR(x[0], a, 1e-5 * a) << s.BriefReport();
    EXPECT_NEAR(x[1], b, 1e-5 * b);
    EXPECT_NEAR(x[2], c, 1e-5);
  }
}

TEST(LevenbergMarquardt, BoundsAreRespectedAndActiveBoundIsOptimal) {
  // minimise (x0 + 3)^2 + (x1 - 2)^2 with x0 >= 0.5, x1 <= 1: optimum (0.5, 1).
  auto residual = [](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
    (*r)[0] = x[0] + 3.0;
    (*r)[1] = x[1] - 2.0;
    if (jac != nullptr) jac->setIdentity();
  };
  LmOptions o;
  o.lower_bounds = Eigen::Vector2d(0.5, -1e9);
  o.upper_bounds = Eigen::Vector2d(1e9, 1.0);
  Eigen::VectorXd x = Eigen::Vector2d(40.0, -30.0);
  const LmSummary s = SolveLeastSquares(residual, 2, true, &x, o);
  EXPECT_TRUE(s.Converged()) << s.BriefReport();
  EXPECT_NEAR(x[0], 0.5, 1e-10);
  EXPECT_NEAR(x[1], 1.0, 1e-10);
  EXPECT_LE(s.final_gradient_norm, o.gradient_tolerance);
}

TEST(LevenbergMarquardt, FiniteDifferenceJacobianMatchesAnalytic) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::VectorXd x(2);
    x << u(rng), u(rng);
    Eigen::VectorXd r(2);
    Eigen::MatrixXd analytic(2, 2);
    Rosenbrock(x, &r, &analytic);
    const Eigen::MatrixXd fd = FiniteDifferenceJacobian(Rosenbrock, 2, x);
    EXPECT_TRUE(test::AllNear(fd, analytic, 1e-7, 1e-7));
  }
}

TEST(LevenbergMarquardt, IterationLimitIsAnOutcomeNotAnError) {
  Eigen::VectorXd x = Eigen::Vector2d(-1.2, 1.0);
  LmOptions o;
  o.max_iterations = 1;
  const LmSummary s = SolveLeastSquares(Rosenbrock, 2, true, &x, o);
  EXPECT_EQ(s.termination, LmTermination::kMaxIterations);
  EXPECT_FALSE(s.Converged());
  EXPECT_NE(s.BriefReport().find("max_iterations"), std::string::npos) << s.BriefReport();
}

TEST(LevenbergMarquardt, NonFiniteStartIsReported) {
  auto residual = [](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd*) {
    (*r)[0] = std::log(x[0]);  // NaN for x < 0
  };
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, -1.0);
  const LmSummary s = SolveLeastSquares(residual, 1, false, &x);
  EXPECT_EQ(s.termination, LmTermination::kNonFinite);
  EXPECT_FALSE(s.Converged());
}

TEST(LevenbergMarquardt, BadOptionsThrowInputError) {
  Eigen::VectorXd x = Eigen::Vector2d(0, 0);
  LmOptions o;
  o.parameter_tolerance = -1;
  EXPECT_THROW(SolveLeastSquares(Rosenbrock, 2, true, &x, o), InputError);
  o = LmOptions{};
  o.lower_bounds = Eigen::Vector3d(0, 0, 0);
  EXPECT_THROW(SolveLeastSquares(Rosenbrock, 2, true, &x, o), InputError);
  o = LmOptions{};
  o.lower_bounds = Eigen::Vector2d(1, 1);
  o.upper_bounds = Eigen::Vector2d(0, 2);
  EXPECT_THROW(SolveLeastSquares(Rosenbrock, 2, true, &x, o), InputError);
  EXPECT_THROW(SolveLeastSquares(Rosenbrock, 0, true, &x), InputError);
}

}  // namespace
}  // namespace whirl::fit
