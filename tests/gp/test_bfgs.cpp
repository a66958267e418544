// core/bfgs.h: minima of functions with known minimizers, the Wolfe line search's handling of
// non-finite values, and the summary's outcomes.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/bfgs.h"
#include "support/eigen_near.h"
#include "support/expect_error.h"

namespace whirl {
namespace {

// Rosenbrock's function in n dimensions; minimum 0 at (1, ..., 1).
double Rosenbrock(const Eigen::VectorXd& x, Eigen::VectorXd* g) {
  double f = 0;
  if (g) g->setZero(x.size());
  for (Eigen::Index i = 0; i + 1 < x.size(); ++i) {
    const double a = x(i + 1) - x(i) * x(i), b = 1 - x(i);
    f += 100 * a * a + b * b;
    if (g) {
      (*g)(i) += -400 * a * x(i) - 2 * b;
      (*g)(i + 1) += 200 * a;
    }
  }
  return f;
}

TEST(Bfgs, RosenbrockReachesItsMinimum) {
  for (int n : {2, 6}) {
    Eigen::VectorXd x = Eigen::VectorXd::Constant(n, -1.2);
    x(n - 1) = 1.0;
    const BfgsSummary s = MinimizeBfgs(Rosenbrock, &x);
    EXPECT_TRUE(test::AllNear(x, Eigen::VectorXd::Ones(n), 0, 1e-5)) << s.BriefReport();
    EXPECT_LT(s.final_cost, 1e-10);
    EXPECT_LT(s.final_cost, s.initial_cost);
  }
}

TEST(Bfgs, IllConditionedQuadraticSolvesTheLinearSystem) {
  // f = (x - c)' A (x - c) / 2 with condition number 1e4: the minimizer is c.
  const int n = 8;
  Eigen::MatrixXd q = Eigen::MatrixXd::Random(n, n);
  const Eigen::MatrixXd a = q * q.transpose() + Eigen::MatrixXd::Identity(n, n) * 1e-3 +
                            Eigen::VectorXd::LinSpaced(n, 1, 1e4).asDiagonal().toDenseMatrix();
  const Eigen::VectorXd c = Eigen::VectorXd::LinSpaced(n, -3, 4);
  auto f = [&](const Eigen::VectorXd& x, Eigen::VectorXd* g) {
    const Eigen::VectorXd r = x - c;
    if (g) *g = a * r;
    return 0.5 * r.dot(a * r);
  };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  BfgsOptions o;
  o.gradient_tolerance = 1e-9;
  o.function_tolerance = 0;
  const BfgsSummary s = MinimizeBfgs(f, &x, o);
  EXPECT_EQ(s.termination, BfgsTermination::kGradientTolerance) << s.BriefReport();
  EXPECT_TRUE(test::AllNear(x, c, 1e-8, 1e-8));
}

TEST(Bfgs, NonFiniteValuesShortenTheStep) {
  // f = (x - 2)^2 for x < 2.5, +inf beyond: the first trial steps overshoot into +inf.
  auto f = [](const Eigen::VectorXd& x, Eigen::VectorXd* g) {
    if (x(0) >= 2.5) return std::numeric_limits<double>::infinity();
    if (g) (*g)(0) = 2 * (x(0) - 2);
    return (x(0) - 2) * (x(0) - 2);
  };
  Eigen::VectorXd x = Eigen::VectorXd::Constant(1, -40.0);
  const BfgsSummary s = MinimizeBfgs(f, &x);
  EXPECT_NEAR(x(0), 2.0, 1e-6) << s.BriefReport();
}

TEST(Bfgs, OutcomesAreValues) {
  auto nan = [](const Eigen::VectorXd&, Eigen::VectorXd*) { return std::nan(""); };
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  EXPECT_EQ(MinimizeBfgs(nan, &x).termination, BfgsTermination::kNonFiniteStart);
  BfgsOptions o;
  o.max_iterations = 2;
  x << -1.2, 1;
  const BfgsSummary s = MinimizeBfgs(Rosenbrock, &x, o);
  EXPECT_EQ(s.termination, BfgsTermination::kMaxIterations);
  EXPECT_EQ(s.iterations, 2);
  EXPECT_NE(s.BriefReport().find("max_iterations"), std::string::npos);
}

TEST(Bfgs, InvalidOptionsAreInputErrors) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(2);
  BfgsOptions o;
  o.wolfe_c2 = 1e-5;
  ExpectInputError([&] { MinimizeBfgs(Rosenbrock, &x, o); }, "wolfe_c1");
  o = {};
  o.max_iterations = -1;
  ExpectInputError([&] { MinimizeBfgs(Rosenbrock, &x, o); }, "max_iterations");
}

}  // namespace
}  // namespace whirl
