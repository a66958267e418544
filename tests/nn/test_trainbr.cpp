// trainbr invariants (MATLAB's trainbr): acceptance rule, gamma range, the first epoch's
// updates recomputed independently, stopping reasons, regularization helps on small noisy data,
// the noise estimate, the log-evidence convention, restarts.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>

#include "core/error.h"
#include "core/random.h"
#include "nn/trainbr.h"
#include "support/eigen_near.h"
#include "synthetic.h"

namespace whirl::nn {
namespace {

Network Initial(const std::vector<int>& sizes, std::uint64_t seed) {
  Network net = Network::Zeros(sizes);
  InitNguyenWidrow(seed, &net);
  return net;
}

TEST(TrainBr, AcceptedStepNeverIncreasesFAndGammaStaysInRange) {
  int accepted = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const TrainingData data = synth::SmoothProblem(20, 0.05, seed);
    const Network net = Initial({5, 6, 2}, 100 + seed);
    const int N = net.ParameterCount();
    const TrainResult r = TrainBr(data, net, TrainOptions{}, [&](const EpochInfo& info) {
      if (info.step_accepted) {
        ++accepted;
        EXPECT_LT(info.objective_after_step, info.objective_before) << "epoch " << info.epoch;
      } else {
        EXPECT_EQ(info.objective_after_step, info.objective_before);
      }
      EXPECT_GT(info.gamma, 0.0);
      EXPECT_LE(info.gamma, N);
      EXPECT_GT(info.alpha, 0.0);
      EXPECT_GT(info.beta, 0.0);
    });
    EXPECT_GT(r.summary.gamma, 0.0);
    EXPECT_LE(r.summary.gamma, N);
    EXPECT_LT(r.summary.sse, r.summary.initial_sse);
    EXPECT_TRUE(std::isfinite(r.summary.log_evidence));
  }
  EXPECT_GT(accepted, 0);
}

// One epoch by hand from trainbr's documented rules (nn/trainbr.h), with gamma from the eigenvalues
// of J'J rather than a matrix inverse.
TEST(TrainBr, FirstEpochFollowsTheReferenceRules) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const TrainingData data = synth::SmoothProblem(20, 0.1, 50 + seed);
    const Network net = Initial({5, 6, 2}, seed);
    const int N = net.ParameterCount();
    const double n = 40;
    ForwardCache cache;
    net.Forward(data.inputs, &cache);
    Eigen::MatrixXd J;
    ErrorJacobian(net, cache, &J);
    const Eigen::MatrixXd E = data.targets - cache.output();
    const Eigen::VectorXd e = Eigen::Map<const Eigen::VectorXd>(E.data(), E.size());
    const Eigen::VectorXd w = net.GetParameters();
    const double sse = e.squaredNorm(), ssx = w.squaredNorm();
    double beta = (n - N) / (2 * sse);
    if (!(beta > 0)) beta = 1;
    ASSERT_EQ(beta, 1.0);  // 20 samples, 2 outputs: n - N < 0
    const double alpha = N / (2 * ssx);
    const double F = beta * sse + alpha * ssx;
    const Eigen::MatrixXd jj = J.transpose() * J;
    const Eigen::VectorXd je = J.transpose() * e;
    double mu = 0.005;
    Eigen::VectorXd w1;
    double sse1 = 0, ssx1 = 0;
    for (;; mu *= 10) {
      ASSERT_LE(mu, 1e10);
      Eigen::MatrixXd A = beta * jj + (mu + alpha) * Eigen::MatrixXd::Identity(N, N);
      const Eigen::VectorXd dw = -A.ldlt().solve(beta * je + alpha * w);
      Network n1 = net;
      n1.SetParameters(w + dw);
      const Eigen::MatrixXd E1 = data.targets - n1.Forward(data.inputs);
      sse1 = E1.squaredNorm();
      ssx1 = (w + dw).squaredNorm();
      if (beta * sse1 + alpha * ssx1 < F) {
        w1 = w + dw;
        mu = std::max(mu * 0.1, 1e-20);
        break;
      }
    }
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jj);
    double gamma = 0;
    for (int i = 0; i < N; ++i) {
      const double lambda = std::max(eig.eigenvalues()(i), 0.0);
      gamma += beta * lambda / (beta * lambda + alpha);
    }
    const double alpha1 = gamma / (2 * ssx1);
    const double beta1 = (n - gamma) / (2 * sse1);

    TrainOptions one;
    one.epochs = 1;
    const TrainResult r = TrainBr(data, net, one);
    EXPECT_EQ(r.summary.termination, TrainTermination::kMaxEpochs);
    EXPECT_EQ(r.summary.epochs, 1);
    EXPECT_NEAR(r.summary.initial_cost, F, 1e-12 * F);
    EXPECT_TRUE(whirl::test::AllNear(r.network.GetParameters(), w1, 1e-9, 1e-12));
    EXPECT_NEAR(r.summary.gamma, gamma, 1e-8 * N);
    EXPECT_NEAR(r.summary.alpha, alpha1, 1e-8 * alpha1);
    EXPECT_NEAR(r.summary.beta, beta1, 1e-8 * beta1);
    EXPECT_NEAR(r.summary.mu, mu, 1e-12 * mu);
    EXPECT_NEAR(r.summary.final_cost, beta1 * sse1 + alpha1 * ssx1, 1e-9 * r.summary.final_cost);
  }
}

TrainOptions WithSystem(LinearSystem system, int epochs = 1000) {
  TrainOptions o;
  o.linear_system = system;
  o.epochs = epochs;
  return o;
}

// LinearSystem::kErrors (n x n, push-through and Woodbury) and kWeights (N x N, MATLAB's form)
// are the same algorithm: epoch by epoch they agree to rounding, on both sides of n = N.
TEST(TrainBr, ErrorsAndWeightsFormsTakeTheSameSteps) {
  for (int Q : {8, 20, 30}) {  // n = 16, 40 < N = 50; n = 60 > N
    for (std::uint64_t seed = 1; seed <= 4; ++seed) {
      const TrainingData data = synth::SmoothProblem(Q, 0.05, 10 * Q + seed);
      const Network net = Initial({5, 6, 2}, seed);
      std::vector<EpochInfo> by_weights, by_errors;
      const TrainResult w = TrainBr(data, net, WithSystem(LinearSystem::kWeights, 12),
                                    [&](const EpochInfo& i) { by_weights.push_back(i); });
      const TrainResult e = TrainBr(data, net, WithSystem(LinearSystem::kErrors, 12),
                                    [&](const EpochInfo& i) { by_errors.push_back(i); });
      ASSERT_EQ(by_weights.size(), by_errors.size()) << "Q " << Q << " seed " << seed;
      for (std::size_t k = 0; k < by_weights.size(); ++k) {
        const EpochInfo &a = by_weights[k], &b = by_errors[k];
        EXPECT_EQ(a.step_accepted, b.step_accepted) << "epoch " << a.epoch;
        EXPECT_EQ(a.mu, b.mu) << "epoch " << a.epoch;  // same accept/reject sequence
        EXPECT_NEAR(a.objective, b.objective, 1e-8 * a.objective) << "epoch " << a.epoch;
        EXPECT_NEAR(a.gamma, b.gamma, 1e-8 * 50) << "epoch " << a.epoch;
        EXPECT_NEAR(a.alpha, b.alpha, 1e-8 * a.alpha) << "epoch " << a.epoch;
        EXPECT_NEAR(a.beta, b.beta, 1e-8 * a.beta) << "epoch " << a.epoch;
      }
      EXPECT_TRUE(
          whirl::test::AllNear(w.network.GetParameters(), e.network.GetParameters(), 1e-7, 1e-9))
          << "Q " << Q << " seed " << seed;
      EXPECT_NEAR(w.summary.log_evidence, e.summary.log_evidence,
                  1e-8 * std::abs(w.summary.log_evidence));
      EXPECT_TRUE(whirl::test::AllNear(w.posterior_covariance, e.posterior_covariance, 1e-6,
                                       1e-9 * w.posterior_covariance.norm()));
    }
  }
}

// kAuto is kErrors below n = N and kWeights from there (bit for bit).
TEST(TrainBr, AutoPicksTheSmallerSystem) {
  for (int Q : {20, 25, 30}) {  // n = 40, 50, 60 against N = 50
    const TrainingData data = synth::SmoothProblem(Q, 0.05, Q);
    const Network net = Initial({5, 6, 2}, 7);
    const Eigen::VectorXd automatic =
        TrainBr(data, net, WithSystem(LinearSystem::kAuto, 30)).network.GetParameters();
    const LinearSystem expected = 2 * Q < 50 ? LinearSystem::kErrors : LinearSystem::kWeights;
    EXPECT_EQ(automatic, TrainBr(data, net, WithSystem(expected, 30)).network.GetParameters())
        << "Q " << Q;
  }
}

TEST(TrainBr, StopsForEachDocumentedReason) {
  const TrainingData data = synth::SmoothProblem(20, 0.05, 3);
  const Network net = Initial({5, 6, 2}, 3);
  TrainOptions o;
  o.epochs = 0;
  TrainResult r = TrainBr(data, net, o);
  EXPECT_EQ(r.summary.termination, TrainTermination::kMaxEpochs);
  EXPECT_EQ(r.summary.epochs, 0);
  EXPECT_EQ(r.network.GetParameters(), net.GetParameters());

  o = TrainOptions{};
  o.goal = 1e9;
  r = TrainBr(data, net, o);
  EXPECT_EQ(r.summary.termination, TrainTermination::kGoalMet);
  EXPECT_NE(r.summary.message.find("goal"), std::string::npos) << r.summary.message;

  o = TrainOptions{};
  o.min_grad = 1e9;
  r = TrainBr(data, net, o);
  EXPECT_EQ(r.summary.termination, TrainTermination::kMinGradient);
  EXPECT_NE(r.summary.message.find("min_grad = 1e+09"), std::string::npos) << r.summary.message;

  o = TrainOptions{};
  o.mu_max = 1e-2;  // one rejection pushes mu past it
  r = TrainBr(data, net, o);
  EXPECT_TRUE(r.summary.termination == TrainTermination::kMaxMu ||
              r.summary.termination == TrainTermination::kMaxEpochs)
      << r.summary.BriefReport();

  // Default options end for one of the four reasons, and the report names it with numbers.
  r = TrainBr(data, net, TrainOptions{});
  EXPECT_NE(r.summary.BriefReport().find(ToString(r.summary.termination)), std::string::npos);
  EXPECT_EQ(ParseTermination(ToString(r.summary.termination)), r.summary.termination);
}

// brnn's rule on hand-made sequences: the spread is the largest of the LAST three consecutive
// differences; fewer than four values never stop.
TEST(TrainBr, ObjectiveSpreadFollowsHandMadeSequences) {
  EXPECT_TRUE(std::isinf(ObjectiveSpread({})));
  EXPECT_TRUE(std::isinf(ObjectiveSpread({5.0, 5.0, 5.0})));
  EXPECT_DOUBLE_EQ(ObjectiveSpread({5.0, 5.0, 5.0, 5.0}), 0.0);
  // Differences 10, 1, 0.5, 0.25: only the last three count.
  EXPECT_DOUBLE_EQ(ObjectiveSpread({30.0, 20.0, 19.0, 18.5, 18.25}), 1.0);
  // An increase counts by its absolute value.
  EXPECT_DOUBLE_EQ(ObjectiveSpread({1.0, 1.0005, 1.0, 1.002}), 0.002);
  // Where a hand-made F sequence crosses change = 0.001: 10 + 2^-k is stalled once the last three
  // differences 2^-(k-1) - 2^-k = 2^-k ... are all below 0.001, i.e. the oldest 2^-(k-2) < 0.001.
  std::vector<double> f;
  int stop_at = -1;
  for (int k = 0; k < 30 && stop_at < 0; ++k) {
    f.push_back(10.0 + std::ldexp(1.0, -k));
    if (ObjectiveSpread(f) < 0.001) stop_at = k;
  }
  EXPECT_EQ(stop_at, 12);  // differences 2^-10, 2^-11, 2^-12 (2^-10 = 0.00098 < 0.001 > 2^-9)
}

// In TrainBr the rule stops exactly at the first epoch whose last four after-step objectives
// (seen through the callback) have consecutive changes below `change`; change = 0 is MATLAB's run.
TEST(TrainBr, ChangeRuleStopsWhereTheObjectivesSay) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const TrainingData data = synth::SmoothProblem(20, 0.1, 70 + seed);
    const Network net = Initial({5, 6, 2}, seed);
    TrainOptions o;
    o.change = 0.001;
    std::vector<double> after;
    int expected_stop = -1;
    const TrainResult r = TrainBr(data, net, o, [&](const EpochInfo& info) {
      after.push_back(info.objective_after_step);
      if (expected_stop < 0 && ObjectiveSpread(after) < o.change) expected_stop = info.epoch;
    });
    if (r.summary.termination == TrainTermination::kObjectiveStalled) {
      EXPECT_EQ(r.summary.epochs, expected_stop) << "seed " << seed;
    } else {  // a MATLAB criterion (tested first) ended the run at or before that epoch
      EXPECT_TRUE(expected_stop == -1 || expected_stop == r.summary.epochs)
          << "seed " << seed << ": " << r.summary.BriefReport();
    }
    // Off: the same start runs to MATLAB's own criteria and is never stalled.
    const TrainResult m = TrainBr(data, net, TrainOptions{});
    EXPECT_NE(m.summary.termination, TrainTermination::kObjectiveStalled);
    EXPECT_GE(m.summary.epochs, r.summary.epochs);
  }
  TrainOptions bad;
  bad.change = -1;
  EXPECT_THROW(bad.Validate(), InputError);
}

TEST(TrainBr, RegularizationBeatsPlainLmOnTwentyNoisySamples) {
  const TrainingData test_set = synth::SmoothProblem(400, 0.0, 999);
  double mse_br = 0, mse_lm = 0;
  const int runs = 8;
  for (int s = 1; s <= runs; ++s) {
    const TrainingData data = synth::SmoothProblem(20, 0.1, 200 + s);
    const Network net = Initial({5, 6, 2}, 300 + s);
    TrainOptions lm;
    lm.regularization = Regularization::kNone;
    const TrainResult br = TrainBr(data, net, TrainOptions{});
    const TrainResult plain = TrainBr(data, net, lm);
    EXPECT_LE(plain.summary.sse, br.summary.sse * 1.0001 + 1e-12);  // LM fits training data closer
    mse_br += (test_set.targets - br.network.Forward(test_set.inputs)).squaredNorm() / 800.0;
    mse_lm += (test_set.targets - plain.network.Forward(test_set.inputs)).squaredNorm() / 800.0;
  }
  mse_br /= runs;
  mse_lm /= runs;
  EXPECT_LT(mse_br, mse_lm) << "trainbr test MSE " << mse_br << " vs plain LM " << mse_lm;
}

// The noise estimate 1/(2 beta) = ssE/(n - gamma) matches the true noise when the model can
// represent the function (teacher network of the same size).
TEST(TrainBr, NoiseVarianceMatchesTrueNoise) {
  const double sigma = 0.1;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    Network teacher = Initial({5, 6, 2}, 900 + seed);
    Rng rng(seed);
    const int Q = 300;
    TrainingData d;
    d.inputs.resize(5, Q);
    for (int q = 0; q < Q; ++q)
      for (int i = 0; i < 5; ++i) d.inputs(i, q) = rng.Uniform(-1, 1);
    d.targets = teacher.Forward(d.inputs);
    for (int q = 0; q < Q; ++q)
      for (int k = 0; k < 2; ++k) d.targets(k, q) += sigma * synth::Gaussian(&rng);
    d.target_scaling = MapMinMax::Identity(2);
    const TrainResult r = TrainBr(d, Initial({5, 6, 2}, seed), TrainOptions{});
    EXPECT_NEAR(r.summary.noise_variance, r.summary.sse / (600 - r.summary.gamma),
                1e-6 * r.summary.noise_variance);
    EXPECT_GT(r.summary.noise_variance, 0.7 * sigma * sigma) << r.summary.BriefReport();
    EXPECT_LT(r.summary.noise_variance, 1.3 * sigma * sigma) << r.summary.BriefReport();
  }
}

// Our closed form (MATLAB alpha, beta) equals MacKay's evidence with alpha_M = 2 alpha,
// beta_M = 2 beta, E_D = ssE/2, E_W = ssX/2, A = 2 H, computed from the eigenvalues of J'J.
TEST(TrainBr, LogEvidenceEqualsMacKaysFormInHisConvention) {
  const TrainingData data = synth::SmoothProblem(20, 0.1, 11);
  const TrainResult r = TrainBr(data, Initial({5, 6, 2}, 11), TrainOptions{});
  ForwardCache cache;
  r.network.Forward(data.inputs, &cache);
  Eigen::MatrixXd J;
  ErrorJacobian(r.network, cache, &J);
  const auto& s = r.summary;
  const double aM = 2 * s.alpha, bM = 2 * s.beta, N = 50, n = 40;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(J.transpose() * J);
  double log_det_A = 0;
  for (int i = 0; i < 50; ++i) log_det_A += std::log(bM * std::max(eig.eigenvalues()(i), 0.0) + aM);
  const double mackay = -bM * s.sse / 2 - aM * s.sum_squared_weights / 2 - 0.5 * log_det_A +
                        N / 2 * std::log(aM) + n / 2 * std::log(bM) - n / 2 * std::log(2 * M_PI) +
                        std::lgamma(7.0) + 6 * std::log(2.0);
  EXPECT_NEAR(s.log_evidence, mackay, 1e-8 * std::abs(mackay));
  // Posterior covariance = A^-1.
  const Eigen::MatrixXd A = bM * J.transpose() * J + aM * Eigen::MatrixXd::Identity(50, 50);
  EXPECT_TRUE(whirl::test::AllNear(Eigen::MatrixXd(A * r.posterior_covariance),
                                   Eigen::MatrixXd::Identity(50, 50), 0, 1e-8));
}

TEST(TrainBr, RestartsKeepTheHighestEvidenceAndAreReproducible) {
  const TrainingData data = synth::SmoothProblem(20, 0.1, 21);
  const RestartResult r = TrainBrRestarts(data, {5, 6, 2}, 40, 4, TrainOptions{});
  ASSERT_EQ(r.runs.size(), 4u);
  for (std::size_t k = 0; k < r.runs.size(); ++k) {
    EXPECT_EQ(r.runs[k].seed, 40 + k);
    EXPECT_LE(r.runs[k].log_evidence, r.best.summary.log_evidence);
    const TrainResult single = TrainBr(data, Initial({5, 6, 2}, 40 + k), TrainOptions{});
    EXPECT_EQ(single.summary.log_evidence, r.runs[k].log_evidence);  // bit-identical rerun
  }
  EXPECT_EQ(r.best.init_seed, r.runs[r.best_index].seed);
  EXPECT_THROW(TrainBrRestarts(data, {5, 6, 2}, 1, 0, TrainOptions{}), InputError);
}

TEST(TrainBr, RejectsInconsistentDataAndBadOptions) {
  TrainingData data = synth::SmoothProblem(10, 0.1, 1);
  const Network net = Initial({5, 6, 2}, 1);
  TrainingData bad = data;
  bad.targets = data.targets.topRows(1);
  EXPECT_THROW(TrainBr(bad, net, TrainOptions{}), InputError);
  bad = data;
  bad.inputs(2, 3) = std::nan("");
  EXPECT_THROW(TrainBr(bad, net, TrainOptions{}), InputError);
  TrainOptions o;
  o.mu_dec = 2;
  try {
    TrainBr(data, net, o);
    FAIL() << "mu_dec = 2 accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("mu_dec"), std::string::npos) << e.what();
  }
  o = TrainOptions{};
  o.epochs = -1;
  EXPECT_THROW(TrainBr(data, net, o), InputError);
}


// The symmetry term counts ln(2^A S! / (S - A)!) for A active neurons of S (hand-computed).
TEST(TrainBr, LogEvidenceSymmetryTermCountsOnlyActiveNeurons) {
  auto ev = [](const std::vector<int>& active) {
    return LogEvidence(3.0, 2.0, 0.5, 4.0, 7.0, 66, 40, {5, 8, 2}, active);
  };
  EXPECT_DOUBLE_EQ(ev({}), ev({8}));
  EXPECT_NEAR(ev({8}) - ev({0}), 8 * std::log(2.0) + std::log(40320.0), 1e-12);
  EXPECT_NEAR(ev({3}) - ev({0}), 3 * std::log(2.0) + std::log(8.0 * 7 * 6), 1e-12);
  // no hidden layer, no symmetry term: equal to 0 active neurons
  EXPECT_NEAR(LogEvidence(3.0, 2.0, 0.5, 4.0, 7.0, 66, 40, {5, 2}), ev({0}), 1e-12);
  EXPECT_THROW(ev({1, 2}), InputError);
}

// gamma_i = 1 - alpha (H^-1)_ii with H^-1 = 2 A^-1: the prior's covariance (2 alpha)^-1 I gives
// gamma_i = 0 (nothing active); a covariance the data have shrunk gives gamma_i near 1.
TEST(TrainBr, ActiveHiddenUnitsFollowTheWellDeterminedParameters) {
  const Network net = Network::Zeros({5, 4, 2});
  const int N = net.ParameterCount();  // 4 * 6 + 2 * 5 = 34
  ASSERT_EQ(N, 34);
  const double alpha = 0.7;
  const Eigen::VectorXd a = Eigen::VectorXd::Constant(N, alpha);
  Eigen::MatrixXd prior = Eigen::MatrixXd::Identity(N, N) / (2 * alpha);
  EXPECT_EQ(ActiveHiddenUnits(net, prior, a), std::vector<int>{0});
  EXPECT_EQ(ActiveHiddenUnits(net, 1e-9 * Eigen::MatrixXd::Identity(N, N), a),
            std::vector<int>{4});
  // neuron 2 determined through its two outgoing weights alone: gamma 2 >= 0.5
  Eigen::MatrixXd one = prior;
  for (int k = 0; k < 2; ++k) one(net.WeightIndex(1, k, 2), net.WeightIndex(1, k, 2)) = 1e-9;
  EXPECT_EQ(ActiveHiddenUnits(net, one, a), std::vector<int>{1});
  // neuron 0 with gamma 0.4 in its bias only: below kActiveUnitGamma
  Eigen::MatrixXd below = prior;
  below(net.BiasIndex(0, 0), net.BiasIndex(0, 0)) = (1 - 0.4) / (2 * alpha);
  EXPECT_EQ(ActiveHiddenUnits(net, below, a), std::vector<int>{0});
  below(net.WeightIndex(0, 0, 3), net.WeightIndex(0, 0, 3)) = (1 - 0.2) / (2 * alpha);
  EXPECT_EQ(ActiveHiddenUnits(net, below, a), std::vector<int>{1});  // 0.4 + 0.2 >= 0.5
  EXPECT_THROW(ActiveHiddenUnits(net, prior, Eigen::VectorXd::Constant(N - 1, alpha)),
               InputError);
}


// For a network without a hidden layer (linear) the Laplace evidence is exact: at the most
// probable weights for alpha, beta, LogEvidence must equal the closed-form marginal likelihood
// of Bayesian linear regression, per output t_k ~ N(0, I / (2 beta) + Phi Phi' / (2 alpha)) with
// Phi = [1, x'] (MATLAB convention: F = beta ssE + alpha ssX, so noise variance 1 / (2 beta) and
// prior variance 1 / (2 alpha)).
TEST(TrainBr, LogEvidenceOfALinearNetworkIsTheClosedFormMarginalLikelihood) {
  const TrainingData d = synth::SmoothProblem(15, 0.1, 21);
  const int Q = 15, S = 2;
  const double alpha = 0.8, beta = 12.0;
  Eigen::MatrixXd phi(Q, 6);
  phi.col(0).setOnes();
  phi.rightCols(5) = d.inputs.transpose();
  const Eigen::MatrixXd h_k =
      beta * phi.transpose() * phi + alpha * Eigen::MatrixXd::Identity(6, 6);
  double sse = 0, ssx = 0, log_det_h = 0, closed = 0;
  const Eigen::MatrixXd C = Eigen::MatrixXd::Identity(Q, Q) / (2 * beta) +
                            phi * phi.transpose() / (2 * alpha);
  const Eigen::LLT<Eigen::MatrixXd> c_llt(C);
  const Eigen::LLT<Eigen::MatrixXd> h_llt(h_k);
  for (int k = 0; k < S; ++k) {
    const Eigen::VectorXd t = d.targets.row(k).transpose();
    const Eigen::VectorXd w = h_llt.solve(beta * phi.transpose() * t);  // most probable weights
    sse += (t - phi * w).squaredNorm();
    ssx += w.squaredNorm();
    log_det_h += 2 * h_llt.matrixLLT().diagonal().array().log().sum();
    const Eigen::VectorXd ci_t = c_llt.solve(t);
    closed += -0.5 * t.dot(ci_t) - c_llt.matrixLLT().diagonal().array().log().sum() -
              0.5 * Q * std::log(2 * M_PI);
  }
  const double laplace = LogEvidence(sse, ssx, alpha, beta, log_det_h, 12, S * Q, {5, 2});
  EXPECT_NEAR(laplace, closed, 1e-9 * std::abs(closed));
}

// The same closed form against trainbr itself on a 5-2 network (the default's linear candidate):
// run to MATLAB's criteria, its final weights are the most probable ones for (nearly) its final
// alpha, beta, so its reported evidence is the exact marginal likelihood there.
TEST(TrainBr, LinearNetworkTrainsToTheClosedFormEvidence) {
  const TrainingData d = synth::SmoothProblem(15, 0.1, 22);
  Network net = Network::Zeros({5, 2});
  InitNguyenWidrow(3, &net);
  const TrainResult r = TrainBr(d, net, TrainOptions{});
  const double alpha = r.summary.alpha, beta = r.summary.beta;
  const int Q = 15;
  Eigen::MatrixXd phi(Q, 6);
  phi.col(0).setOnes();
  phi.rightCols(5) = d.inputs.transpose();
  const Eigen::LLT<Eigen::MatrixXd> c_llt(Eigen::MatrixXd::Identity(Q, Q) / (2 * beta) +
                                          phi * phi.transpose() / (2 * alpha));
  double closed = 0;
  for (int k = 0; k < 2; ++k) {
    const Eigen::VectorXd t = d.targets.row(k).transpose();
    closed += -0.5 * t.dot(c_llt.solve(t)) - c_llt.matrixLLT().diagonal().array().log().sum() -
              0.5 * Q * std::log(2 * M_PI);
  }
  EXPECT_GT(r.summary.gamma, 1.0) << r.summary.BriefReport();
  EXPECT_NEAR(r.summary.log_evidence, closed, 1e-8) << r.summary.BriefReport();
}

}  // namespace
}  // namespace whirl::nn
