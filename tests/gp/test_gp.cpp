// gp/gp.h: the marginal likelihood against a direct dense evaluation, its gradient against finite
// differences, the closed-form leave-one-out against refits without each row, interpolation,
// recovery of a known noise level and irrelevant inputs, and the JSON round trip.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdlib>

#include "core/numbers.h"
#include "gp/gp.h"
#include "support/eigen_near.h"
#include "support/expect_error.h"

namespace whirl::gp {
namespace {

struct Data {
  Eigen::MatrixXd x;  // d x n
  Eigen::VectorXd y;
};

// y = sin(x1) + 0.5 x2 + noise_sd * N(0,1)-ish (sum of uniforms), x in [0, 4]^d.
Data MakeData(int d, int n, double noise_sd, unsigned seed) {
  std::srand(seed);
  Data data;
  data.x = 2.0 * (Eigen::MatrixXd::Random(d, n).array() + 1.0);
  data.y.resize(n);
  for (int q = 0; q < n; ++q) {
    const double e = (Eigen::VectorXd::Random(12).sum()) / 2.0;  // sd 1
    data.y(q) = std::sin(data.x(0, q)) + 0.5 * data.x(1, q) + noise_sd * e;
  }
  return data;
}

// -ln N(u | H b, K) with b by GLS, by dense inverse and LU determinant.
double DenseNlml(Kernel kernel, Mean mean, const Eigen::MatrixXd& z, const Eigen::VectorXd& u,
                 const Eigen::VectorXd& theta, double floor) {
  const int d = static_cast<int>(z.rows()), n = static_cast<int>(z.cols());
  Eigen::MatrixXd k(n, n);
  for (int p = 0; p < n; ++p)
    for (int q = 0; q < n; ++q) {
      double r2 = 0;
      for (int i = 0; i < d; ++i) r2 += std::pow((z(i, p) - z(i, q)) / std::exp(theta(i)), 2);
      const double r = std::sqrt(r2), sf2 = std::exp(2 * theta(d));
      k(p, q) = kernel == Kernel::kSquaredExponential
                    ? sf2 * std::exp(-r2 / 2)
                    : sf2 * (1 + std::sqrt(5.0) * r + 5 * r2 / 3) * std::exp(-std::sqrt(5.0) * r);
    }
  k.diagonal().array() += std::exp(2 * theta(d + 1)) + floor;
  Eigen::MatrixXd h(n, MeanSize(mean, d));
  h.col(0).setOnes();
  if (mean == Mean::kLinear) h.rightCols(d) = z.transpose();
  const Eigen::MatrixXd ki = k.inverse();
  const Eigen::VectorXd b = (h.transpose() * ki * h).inverse() * h.transpose() * ki * u;
  const Eigen::VectorXd r = u - h * b;
  return 0.5 * r.dot(ki * r) + 0.5 * std::log(k.fullPivLu().determinant()) +
         0.5 * n * std::log(2 * kPi);
}

const Kernel kKernels[] = {Kernel::kSquaredExponential, Kernel::kMatern52};
const Mean kMeans[] = {Mean::kConstant, Mean::kLinear};

TEST(GpLikelihood, EqualsTheDenseFormula) {
  const Data data = MakeData(3, 12, 0.1, 1);
  Eigen::VectorXd theta(5);
  theta << 0.3, -0.2, 0.8, 0.1, -1.5;
  for (Kernel k : kKernels)
    for (Mean m : kMeans)
      EXPECT_NEAR(NegLogMarginalLikelihood(k, m, data.x, data.y, theta, 1e-6, nullptr),
                  DenseNlml(k, m, data.x, data.y, theta, 1e-6), 1e-8)
          << ToString(k) << " " << ToString(m);
}

// A GP fitted to the data with the given kernel and mean, every other option the default.
Gp FitWith(const Data& data, Kernel k, Mean m) {
  GpOptions o;
  o.kernel = k;
  o.mean = m;
  return FitGp(data.x, data.y, o);
}

TEST(GpLikelihood, FittedLogMarginalLikelihoodIsMinusTheDenseFormula) {
  const Data data = MakeData(3, 20, 0.1, 4);
  for (Kernel k : kKernels)
    for (Mean m : kMeans) {
      const Gp gp = FitWith(data, k, m);
      EXPECT_NEAR(LogMarginalLikelihood(gp),
                  -DenseNlml(k, m, gp.z, gp.u, gp.theta, gp.min_noise_variance), 1e-8)
          << ToString(k) << " " << ToString(m);
    }
}

TEST(GpLikelihood, GradientMatchesCentralDifferences) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Data data = MakeData(4, 15, 0.2, seed);
    std::srand(100 + seed);
    const Eigen::VectorXd theta = 0.7 * Eigen::VectorXd::Random(6);
    for (Kernel k : kKernels)
      for (Mean m : kMeans) {
        Eigen::VectorXd g(6), fd(6);
        NegLogMarginalLikelihood(k, m, data.x, data.y, theta, 1e-6, &g);
        for (int j = 0; j < 6; ++j) {
          const double h = 1e-5;
          Eigen::VectorXd tp = theta, tm = theta;
          tp(j) += h;
          tm(j) -= h;
          fd(j) = (NegLogMarginalLikelihood(k, m, data.x, data.y, tp, 1e-6, nullptr) -
                   NegLogMarginalLikelihood(k, m, data.x, data.y, tm, 1e-6, nullptr)) /
                  (2 * h);
        }
        EXPECT_TRUE(test::AllNear(g, fd, 1e-5, 1e-6)) << ToString(k) << " " << ToString(m);
      }
  }
}

TEST(GpLeaveOneOut, EqualsRefitsWithoutEachRow) {
  const Data data = MakeData(3, 14, 0.2, 7);
  for (Kernel k : kKernels)
    for (Mean m : kMeans) {
      const Gp gp = FitWith(data, k, m);
      const LeaveOneOut loo = LeaveOneOutGp(gp);
      for (int i = 0; i < 14; ++i) {
        Gp without = gp;  // same hyperparameters and standardization, row i removed
        const int n = 13;
        without.z.resize(3, n);
        without.u.resize(n);
        for (int q = 0, c = 0; q < 14; ++q)
          if (q != i) {
            without.z.col(c) = gp.z.col(q);
            without.u(c++) = gp.u(q);
          }
        without.Factorize();
        const GpPrediction p = PredictGp(without, data.x.col(i));
        EXPECT_NEAR(loo.residual(i), data.y(i) - p.mean(0), 1e-7 * gp.target_scale);
        EXPECT_NEAR(loo.latent_variance(i), p.latent_variance(0),
                    1e-7 * gp.target_scale * gp.target_scale);
      }
    }
}

// df = sum_i d u_hat_i / d u_i (u_hat: PredictGp's means at the training rows, standardized,
// hyperparameters fixed), by central differences; and it lies between the mean's coefficient
// count and the row count.
TEST(GpDegreesOfFreedom, EqualTheTraceOfTheSmootherByFiniteDifferences) {
  const Data data = MakeData(3, 14, 0.2, 5);
  for (Kernel k : kKernels)
    for (Mean m : {Mean::kConstant, Mean::kLinear}) {
      GpOptions o;
      o.kernel = k;
      o.mean = m;
      const Gp gp = FitGp(data.x, data.y, o);
      auto fitted = [&](const Eigen::VectorXd& u, int i) {  // standardized fitted mean at row i
        Gp g = gp;
        g.u = u;
        g.Factorize();
        return (PredictGp(g, data.x.col(i)).mean(0) - g.target_shift) / g.target_scale;
      };
      double trace = 0;
      const double h = 1e-5;
      for (int i = 0; i < 14; ++i) {
        Eigen::VectorXd up = gp.u, down = gp.u;
        up(i) += h;
        down(i) -= h;
        trace += (fitted(up, i) - fitted(down, i)) / (2 * h);
      }
      const double df = EffectiveDegreesOfFreedom(gp);
      EXPECT_NEAR(df, trace, 1e-6) << ToString(k) << " " << ToString(m);
      EXPECT_GE(df, MeanSize(m, 3) - 1e-9);
      EXPECT_LE(df, 14 + 1e-9);
    }
}

TEST(GpFit, RecoversTheNoiseLevelAndIgnoresAnIrrelevantInput) {
  // y depends on inputs 0 and 1 only; input 2 is irrelevant; noise sd 0.1.
  const Data data = MakeData(3, 80, 0.1, 3);
  for (Kernel k : kKernels) {
    GpOptions o;
    o.kernel = k;
    GpSummary s;
    const Gp gp = FitGp(data.x, data.y, o, &s);
    const double noise_sd = std::sqrt(gp.SigmaN2()) * gp.target_scale;
    EXPECT_GT(noise_sd, 0.06) << s.BriefReport();
    EXPECT_LT(noise_sd, 0.15) << s.BriefReport();
    EXPECT_GT(gp.theta(2), gp.theta(0) + 1.0) << "irrelevant input's length scale is not longer";
    const Data test = MakeData(3, 200, 0.0, 4);
    const GpPrediction p = PredictGp(gp, test.x);
    EXPECT_LT(std::sqrt((p.mean - test.y).array().square().mean()), 0.1);
  }
}

TEST(GpFit, InterpolatesNoiseFreeDataAndVarianceVanishesThere) {
  const Data data = MakeData(2, 10, 0.0, 5);
  const Gp gp = FitGp(data.x, data.y, {});
  const GpPrediction p = PredictGp(gp, data.x);
  EXPECT_TRUE(test::AllNear(p.mean, data.y, 0, 1e-3));
  EXPECT_LT(p.latent_variance.maxCoeff(), 1e-4 * gp.target_scale * gp.target_scale);
}

TEST(GpFit, JsonRoundTripPredictsIdentically) {
  const Data data = MakeData(3, 20, 0.1, 9);
  GpOptions o;
  o.mean = Mean::kLinear;
  Gp gp = FitGp(data.x, data.y, o);
  gp.noise_variance *= 2;  // a calibrated level is kept
  const Gp back = nlohmann::json::parse(nlohmann::json(gp).dump()).get<Gp>();
  const Data test = MakeData(3, 7, 0.1, 10);
  const GpPrediction a = PredictGp(gp, test.x), b = PredictGp(back, test.x);
  EXPECT_TRUE(test::AllNear(a.mean, b.mean, 1e-12));
  EXPECT_TRUE(test::AllNear(a.Stddev(), b.Stddev(), 1e-12));
}

TEST(GpFit, BadInputIsAnInputError) {
  const Data data = MakeData(3, 20, 0.1, 9);
  GpOptions o;
  o.mean = Mean::kLinear;
  ExpectInputError([&] { FitGp(data.x.leftCols(5), data.y.head(5), o); }, "needs at least 6");
  ExpectInputError([&] { FitGp(data.x, data.y.head(5), {}); }, "targets");
  o.restarts = 0;
  ExpectInputError([&] { FitGp(data.x, data.y, o); }, "restarts");
  nlohmann::json j = FitGp(data.x, data.y, {});
  j["theta"] = {1.0, 2.0};
  ExpectInputError([&] { j.get<Gp>(); }, "theta");
  ExpectInputError([] { ParseKernel("rbf"); }, "matern52");
}

}  // namespace
}  // namespace whirl::gp

namespace whirl::gp {
namespace {

TEST(GpFit, IsotropicKernelSharesOneLengthScaleAtAStationaryPoint) {
  // GpOptions::isotropic: every length scale equal, and the likelihood stationary along the
  // shared log length scale (the sum of the ARD gradient's length components) and in s_f, s_n;
  // the ARD fit, a superset of the isotropic models, reaches at most the isotropic NLML.
  const Data data = MakeData(3, 40, 0.1, 7);
  for (Kernel k : kKernels) {
    GpOptions o;
    o.kernel = k;
    o.isotropic = true;
    o.length_prior_sd = 0;  // maximum likelihood: the summary's objective is the NLML
    o.bfgs.gradient_tolerance = 1e-7;
    o.bfgs.function_tolerance = 1e-12;
    GpSummary iso_summary, ard_summary;
    const Gp iso = FitGp(data.x, data.y, o, &iso_summary);
    ASSERT_EQ(iso.theta.size(), 5);
    EXPECT_EQ(iso.theta(1), iso.theta(0));
    EXPECT_EQ(iso.theta(2), iso.theta(0));
    Eigen::VectorXd g;
    const double nlml =
        NegLogMarginalLikelihood(k, iso.mean, iso.z, iso.u, iso.theta, iso.min_noise_variance, &g);
    EXPECT_NEAR(nlml, iso_summary.nlml, 1e-9);
    EXPECT_NEAR(g.head(3).sum(), 0.0, 1e-4) << iso_summary.BriefReport();
    EXPECT_NEAR(g(3), 0.0, 1e-4);
    EXPECT_NEAR(g(4), 0.0, 1e-4);
    EXPECT_GT(std::abs(g(0) - g(2)), 1e-3) << "the ARD gradient is not zero: the test would be moot";
    o.isotropic = false;
    FitGp(data.x, data.y, o, &ard_summary);
    EXPECT_LE(ard_summary.nlml, iso_summary.nlml + 1e-6);
    // A warm start from an ARD theta stays isotropic.
    o.isotropic = true;
    const Gp warm = FitGpFrom(data.x, data.y, o, FitGp(data.x, data.y, GpOptions{}).theta);
    EXPECT_EQ(warm.theta(2), warm.theta(0));
  }
}

// GpOptions::length_prior_sd: the fit maximizes the likelihood times the log-normal prior, so at
// its optimum dNLML/d ln l_i = -(ln l_i - LengthPriorMean(d)) / sd^2 for every length scale; and
// the prior pulls the log length scales towards its mean.
TEST(GpFit, LengthPriorIsStationaryInThePosterior) {
  const Data data = MakeData(3, 25, 0.1, 11);
  EXPECT_NEAR(LengthPriorMean(5), std::sqrt(2.0) + 0.5 * std::log(5.0) + 0.5 * std::log(12.0),
              1e-15);
  for (Kernel k : kKernels) {
    GpOptions o;
    o.kernel = k;
    o.bfgs.gradient_tolerance = 1e-8;
    o.bfgs.function_tolerance = 1e-14;
    const Gp map = FitGp(data.x, data.y, o);
    Eigen::VectorXd g;
    NegLogMarginalLikelihood(k, map.mean, map.z, map.u, map.theta, map.min_noise_variance, &g);
    for (int i = 0; i < 3; ++i)
      EXPECT_NEAR(g(i), -(map.theta(i) - LengthPriorMean(3)) / (o.length_prior_sd * o.length_prior_sd),
                  1e-4)
          << "kernel " << ToString(k) << " length " << i;
    EXPECT_NEAR(g(3), 0.0, 1e-4);
    EXPECT_NEAR(g(4), 0.0, 1e-4);
    o.length_prior_sd = 0;
    const Gp ml = FitGp(data.x, data.y, o);
    const double mu = LengthPriorMean(3);
    EXPECT_LT((map.theta.head(3).array() - mu).square().sum(),
              (ml.theta.head(3).array() - mu).square().sum());
  }
}

// The fit evaluates the likelihood many times in buffers it reuses; the value it reports for the
// chosen start is a fresh evaluation's at the hyperparameters it returns (plus the length prior).
TEST(GpFit, ReportedObjectiveIsAFreshEvaluationAtTheFittedPoint) {
  for (const int n : {16, 45, 90})
    for (Kernel k : kKernels)
      for (Mean m : kMeans) {
        const Data data = MakeData(3, n, 0.1, 17 + n);
        GpOptions o;
        o.kernel = k;
        o.mean = m;
        GpSummary s;
        const Gp gp = FitGp(data.x, data.y, o, &s);
        ASSERT_TRUE((gp.theta.array().abs() < 30).all());
        const Eigen::ArrayXd dev =
            (gp.theta.head(3).array() - LengthPriorMean(3)) / o.length_prior_sd;
        const double fresh =
            NegLogMarginalLikelihood(k, m, gp.z, gp.u, gp.theta, gp.min_noise_variance, nullptr) +
            0.5 * dev.square().sum();
        EXPECT_EQ(s.nlml, fresh) << "n " << n << ", " << ToString(k) << ", " << ToString(m);
      }
}

// GpOptions::max_rows keeps every ceil-spread row of a large table (and no other), and
// hyperparameter_rows fits the hyperparameters on a subset while the GP keeps all its rows.
TEST(GpFit, SubsetsOfLargeTables) {
  const Data data = MakeData(2, 50, 0.1, 13);
  GpOptions o;
  o.max_rows = 20;
  o.hyperparameter_rows = 0;
  const Gp sub = FitGp(data.x, data.y, o);
  ASSERT_EQ(sub.rows.size(), 20u);
  ASSERT_EQ(sub.u.size(), 20);
  for (int j = 0; j < 20; ++j) {
    EXPECT_EQ(sub.rows[j], j * 50 / 20);
    EXPECT_NEAR(sub.u(j), (data.y(sub.rows[j]) - sub.target_shift) / sub.target_scale, 1e-12);
  }
  EXPECT_NEAR(sub.target_shift, data.y.mean(), 1e-12);  // standardized by every row
  o.max_rows = 0;
  o.hyperparameter_rows = 20;
  const Gp hyper = FitGp(data.x, data.y, o);
  EXPECT_TRUE(hyper.rows.empty());
  EXPECT_EQ(hyper.u.size(), 50);
  o.hyperparameter_rows = 0;
  const Gp full = FitGp(data.x, data.y, o);
  EXPECT_GT((hyper.theta - full.theta).cwiseAbs().maxCoeff(), 1e-6);
  o.hyperparameter_rows = 50;  // as many as the table: the full fit
  EXPECT_EQ(FitGp(data.x, data.y, o).theta, full.theta);
  o.max_rows = 3;
  ExpectInputError([&] { FitGp(data.x, data.y, o); }, "at least 8");
}

}  // namespace
}  // namespace whirl::gp

namespace whirl::gp {
namespace {

// Data that the mean explains exactly drive the likelihood's noise sd towards 0 (a design's table of
// 8-12 screws of the simulator did: ln s_n = -46.6, and 'whirl train' refused to write its own
// model); the fit keeps ln s_n within the file's rule [-30, 30], so its model saves and loads.
TEST(GpFit, ExactDataGiveASavableNoiseLevel) {
  Eigen::MatrixXd x(2, 14);
  Eigen::VectorXd y(14);
  for (int i = 0; i < 14; ++i) {
    x(0, i) = std::sin(0.9 * i), x(1, i) = std::cos(1.7 * i);
    y(i) = 1 + 2 * x(0, i) - x(1, i);
  }
  GpOptions o;
  o.mean = Mean::kLinear;
  // From a start whose noise sd is already far below the floor, where the likelihood no longer
  // moves it (its gradient vanishes there): the optimizer leaves it at ln s_n = -50.
  Eigen::VectorXd start(4);
  start << 0.5, 0.5, 0.0, -50.0;
  const Gp g = FitGpFrom(x, y, o, start);
  EXPECT_GE(g.theta(g.theta.size() - 1), -30.0);
  nlohmann::json j = g;
  Gp back;
  EXPECT_NO_THROW(from_json(j, back));
}

}  // namespace
}  // namespace whirl::gp
