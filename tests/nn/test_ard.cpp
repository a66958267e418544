// TrainOptions::ard (automatic relevance determination, MacKay): inputs the data do not use are
// switched off and the ARD stage is kept only with a higher evidence; the log evidence and
// posterior covariance of the ARD stage against an independent recomputation; the grouped
// evidence reduces to LogEvidence; files round-trip the setting.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/json_file.h"
#include "core/random.h"
#include "nn/model.h"
#include "nn/trainbr.h"
#include "support/eigen_near.h"
#include "synthetic.h"
#include "support/scratch_dir.h"

namespace whirl::nn {
namespace {

// Outputs depend on inputs 0, 1, 2 only; inputs 3 and 4 are pure noise columns.
TrainingData ThreeOfFiveInputs(int Q, double noise, std::uint64_t seed) {
  Rng rng(seed);
  TrainingData d;
  d.inputs.resize(5, Q);
  d.targets.resize(2, Q);
  for (int q = 0; q < Q; ++q) {
    for (int i = 0; i < 5; ++i) d.inputs(i, q) = rng.Uniform(-1, 1);
    const auto x = d.inputs.col(q);
    d.targets(0, q) = std::sin(1.5 * x(0)) + 0.5 * x(1) * x(2) + noise * synth::Gaussian(&rng);
    d.targets(1, q) =
        0.6 * std::tanh(x(0) + x(1)) + 0.3 * std::cos(2 * x(2)) + noise * synth::Gaussian(&rng);
  }
  d.target_scaling = MapMinMax::Identity(2);
  return d;
}

Network Initial(std::uint64_t seed) {
  Network net = Network::Zeros({5, 6, 2});
  InitNguyenWidrow(seed, &net);
  return net;
}

TrainOptions ArdOptions() {
  TrainOptions o;
  o.change = 1e-3;
  o.ard = true;
  return o;
}

// A finished ARD fit recomputed from its weights: group(p) = i for the first-layer weights from
// input i, 5 for all other weights; H = beta J'J + diag(alpha_group(p)).
struct Recomputed {
  Eigen::VectorXd w;
  Eigen::VectorXi group;
  Eigen::MatrixXd H;
};

Recomputed Recompute(const TrainResult& r, const TrainingData& d) {
  Recomputed x;
  ForwardCache cache;
  r.network.Forward(d.inputs, &cache);
  Eigen::MatrixXd J;
  ErrorJacobian(r.network, cache, &J);
  x.w = r.network.GetParameters();
  x.group = Eigen::VectorXi::Constant(x.w.size(), 5);
  for (int h = 0; h < r.network.layer_sizes[1]; ++h)
    for (int i = 0; i < 5; ++i) x.group(r.network.WeightIndex(0, h, i)) = i;
  x.H = r.summary.beta * J.transpose() * J;
  for (int p = 0; p < x.w.size(); ++p) x.H(p, p) += r.summary.ard_alpha(x.group(p));
  return x;
}

double TestRms(const Network& net, const TrainingData& test) {
  return std::sqrt((test.targets - net.Forward(test.inputs)).squaredNorm() /
                   static_cast<double>(test.targets.size()));
}

TEST(Ard, InputsTheDataDoNotUseGetTheLargestAlphaAndTheFitGeneralizesBetter) {
  const TrainingData test = ThreeOfFiveInputs(500, 0.0, 999);
  double rms_ard = 0, rms_one = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const TrainingData d = ThreeOfFiveInputs(40, 0.05, seed);
    const TrainResult ard = TrainBr(d, Initial(seed), ArdOptions());
    TrainOptions one = ArdOptions();
    one.ard = false;
    const TrainResult plain = TrainBr(d, Initial(seed), one);
    const Eigen::VectorXd& a = ard.summary.ard_alpha;
    ASSERT_EQ(a.size(), 6) << "5 inputs + all other weights";
    EXPECT_GT(std::min(a(3), a(4)), a.head(3).maxCoeff())
        << "seed " << seed << ": alpha " << a.transpose();
    EXPECT_EQ(plain.summary.ard_alpha.size(), 0);
    // The same first stage, then ARD epochs; kept only with a higher evidence.
    EXPECT_GT(ard.summary.log_evidence, plain.summary.log_evidence);
    EXPECT_GT(ard.summary.epochs, plain.summary.epochs);
    EXPECT_NE(ard.summary.message.find("; ARD stage: "), std::string::npos) << ard.summary.message;
    rms_ard += TestRms(ard.network, test);
    rms_one += TestRms(plain.network, test);
  }
  EXPECT_LT(rms_ard, rms_one) << "summed noise-free test RMS over 5 seeds";
}

// The ARD stage's log evidence and posterior covariance from the final weights, recomputed:
// H = beta J'J + diag(alpha_g(i)), ln P = -F - 1/2 ln det H + sum_g N_g/2 ln alpha_g
// + n/2 ln beta - n/2 ln pi + ln(6!) + 6 ln 2, covariance = (2 H)^-1.
TEST(Ard, LogEvidenceAndCovarianceFollowTheGroupedLaplaceForm) {
  const TrainingData d = ThreeOfFiveInputs(30, 0.05, 7);
  const TrainResult r = TrainBr(d, Initial(7), ArdOptions());
  const TrainSummary& s = r.summary;
  ASSERT_EQ(s.ard_alpha.size(), 6) << s.message;
  const Recomputed x = Recompute(r, d);
  const Eigen::VectorXd& w = x.w;
  const Eigen::MatrixXd& H = x.H;
  Eigen::VectorXd group_size = Eigen::VectorXd::Zero(6);
  double prior = 0;
  for (int p = 0; p < w.size(); ++p) {
    group_size(x.group(p)) += 1;
    prior += s.ard_alpha(x.group(p)) * w(p) * w(p);
  }
  EXPECT_EQ(group_size(0), 6);
  EXPECT_EQ(group_size(5), 50 - 30);
  const Eigen::LLT<Eigen::MatrixXd> llt(H);
  ASSERT_EQ(llt.info(), Eigen::Success);
  const double log_det = 2 * llt.matrixL().toDenseMatrix().diagonal().array().log().sum();
  const double sse = (d.targets - r.network.Forward(d.inputs)).squaredNorm();
  const double n = 60;
  double expected = -s.beta * sse - prior - 0.5 * log_det + 0.5 * n * std::log(s.beta) -
                    0.5 * n * std::log(M_PI) + std::lgamma(7.0) + 6 * std::log(2.0);
  for (int g = 0; g < 6; ++g) expected += 0.5 * group_size(g) * std::log(s.ard_alpha(g));
  EXPECT_NEAR(s.log_evidence, expected, 1e-7 * std::abs(expected));
  EXPECT_NEAR(s.sse, sse, 1e-12 * sse);
  EXPECT_TRUE(whirl::test::AllNear(Eigen::MatrixXd(2 * H * r.posterior_covariance),
                                   Eigen::MatrixXd::Identity(50, 50), 0, 1e-6));
}

// At the end of a converged ARD stage the hyperparameters are at MacKay's fixed point, recomputed
// here from H at the final weights: 2 alpha_g ssX_g = gamma_g = N_g - alpha_g trace_g(H^-1) for
// every group below the cap, and 2 beta ssE = n - sum gamma_g.
TEST(Ard, EndsAtTheFixedPointOfTheGroupedReestimation) {
  for (std::uint64_t seed : {11, 12, 13}) {
    const TrainingData d = ThreeOfFiveInputs(40, 0.05, seed);
    TrainOptions o = ArdOptions();
    o.change = 1e-10;
    const TrainResult r = TrainBr(d, Initial(seed), o);
    const TrainSummary& s = r.summary;
    ASSERT_EQ(s.ard_alpha.size(), 6) << s.message;
    const Recomputed x = Recompute(r, d);
    const Eigen::VectorXd& w = x.w;
    const Eigen::VectorXi& group = x.group;
    const Eigen::VectorXd h_inv_diag =
        x.H.llt().solve(Eigen::MatrixXd::Identity(w.size(), w.size())).diagonal();
    double gamma_sum = 0;
    for (int g = 0; g < 6; ++g) {
      double size = 0, trace = 0, ssx = 0;
      for (int p = 0; p < w.size(); ++p)
        if (group(p) == g) {
          size += 1;
          trace += h_inv_diag(p);
          ssx += w(p) * w(p);
        }
      const double gamma = size - s.ard_alpha(g) * trace;
      gamma_sum += gamma;
      if (s.ard_alpha(g) < kArdAlphaMax) {
        EXPECT_NEAR(2 * s.ard_alpha(g) * ssx, gamma, 1e-3 * size)
            << "seed " << seed << " group " << g << ": " << s.message;
      }
    }
    const double sse = (d.targets - r.network.Forward(d.inputs)).squaredNorm();
    EXPECT_NEAR(2 * s.beta * sse, 80 - gamma_sum, 1e-3 * 80) << "seed " << seed;
    EXPECT_NEAR(s.gamma, gamma_sum, 1e-3 * 50);
  }
}

// A first stage that ends on the goal leaves the ARD stage nothing to do: it takes no step and is
// not kept, whatever rounding does to the evidence.
TEST(Ard, AStageWithoutAStepIsNotKept) {
  const TrainingData d = ThreeOfFiveInputs(30, 0.05, 5);
  TrainOptions o = ArdOptions();
  o.goal = 1e9;
  const TrainResult r = TrainBr(d, Initial(5), o);
  EXPECT_EQ(r.summary.termination, TrainTermination::kGoalMet);
  EXPECT_EQ(r.summary.ard_alpha.size(), 0);
  EXPECT_NE(r.summary.message.find("ARD stage not kept (0 accepted steps"), std::string::npos)
      << r.summary.message;
}

// The epoch callback: first-stage epochs 1, 2, ... with ard_stage false, then the ARD stage's
// epochs counting from 1 again with ard_stage true; without --ard never true.
TEST(Ard, CallbackMarksTheStagesAndCountsEachFromOne) {
  const TrainingData d = ThreeOfFiveInputs(30, 0.05, 9);
  for (bool ard : {false, true}) {
    TrainOptions o = ArdOptions();
    o.ard = ard;
    std::vector<std::pair<bool, int>> seen;
    const TrainResult r = TrainBr(d, Initial(9), o, [&](const EpochInfo& info) {
      seen.emplace_back(info.ard_stage, info.epoch);
    });
    ASSERT_FALSE(seen.empty());
    int first = 0, second = 0;
    for (const auto& [stage, epoch] : seen) {
      if (!stage) {
        EXPECT_EQ(second, 0) << "no first-stage epoch after the ARD stage began";
        EXPECT_EQ(epoch, ++first);
      } else {
        EXPECT_EQ(epoch, ++second);
      }
    }
    EXPECT_GT(first, 0);
    if (ard) {
      EXPECT_GT(second, 0);
      EXPECT_EQ(first + second, r.summary.epochs) << r.summary.message;
    } else {
      EXPECT_EQ(second, 0);
    }
  }
}

TEST(Ard, GroupedEvidenceWithEqualAlphasIsLogEvidence) {
  Rng rng(3);
  for (int trial = 0; trial < 200; ++trial) {
    const double sse = rng.Uniform(0.01, 10), beta = rng.Uniform(0.1, 1e4);
    const double alpha = rng.Uniform(1e-3, 10), log_det = rng.Uniform(-50, 300);
    Eigen::VectorXd ssx(6), size(6);
    for (int g = 0; g < 6; ++g) {
      ssx(g) = rng.Uniform(0, 5);
      size(g) = g < 5 ? 6 : 20;
    }
    const double grouped = LogEvidenceGroups(sse, ssx, Eigen::VectorXd::Constant(6, alpha), size,
                                             beta, log_det, 40, {5, 6, 2});
    const double plain = LogEvidence(sse, ssx.sum(), alpha, beta, log_det, 50, 40, {5, 6, 2});
    EXPECT_NEAR(grouped, plain, 1e-9 * (1 + std::abs(plain)));
  }
}

TEST(Ard, NeedsBayesianRegularization) {
  TrainOptions o = ArdOptions();
  o.regularization = Regularization::kNone;
  EXPECT_THROW(o.Validate(), InputError);
}

TEST(Ard, ModelFileKeepsTheSettingAndTheGroupAlphas) {
  ModelTrainOptions o = DefaultTrainingOptions();
  o.train.ard = true;
  o.threads = 1;
  const Model m = TrainModel(synth::SyntheticProcessTable(30, 0.05, 4), o, "synthetic.csv");
  EXPECT_TRUE(m.train_options.ard);
  const auto kept = m.training_summary.ard_alpha.size();
  EXPECT_TRUE(kept == 6 || (kept == 0 && m.training_summary.message.find("ARD stage not kept") !=
                                             std::string::npos))
      << m.training_summary.message;
  const auto path = whirl::test::ScratchDir() /
                    ("whirl_ard_test_" + std::to_string(::getpid()) + ".json");
  SaveModel(path, m);
  const Model back = LoadModel(path);
  EXPECT_TRUE(back.train_options.ard);
  EXPECT_EQ(back.training_summary.ard_alpha, m.training_summary.ard_alpha);
  auto j = ReadJsonFile(path);
  j["training"]["options"]["ard"] = "yes";
  WriteJsonFile(path, j);
  EXPECT_THROW(LoadModel(path), InputError);
  std::filesystem::remove(path);
}

TEST(Ard, ModelValidationChecksTheGroupAlphas) {
  ModelTrainOptions o = DefaultTrainingOptions();
  o.threads = 1;
  o.noise_folds = 0;
  Model m = TrainModel(synth::SyntheticProcessTable(20, 0.05, 4), o, "synthetic.csv");
  EXPECT_NO_THROW(m.Validate());
  m.training_summary.ard_alpha = Eigen::VectorXd::Constant(6, 0.5);
  EXPECT_THROW(m.Validate(), InputError) << "alphas without options.ard";
  m.train_options.ard = true;
  EXPECT_NO_THROW(m.Validate());
  for (double bad : {0.0, -1.0, std::nan(""), HUGE_VAL, 2 * kArdAlphaMax}) {
    m.training_summary.ard_alpha(2) = bad;
    EXPECT_THROW(m.Validate(), InputError) << bad;
  }
  m.training_summary.ard_alpha = Eigen::VectorXd::Constant(5, 0.5);
  EXPECT_THROW(m.Validate(), InputError) << "one alpha per input and one for the rest";
}

// --stop-by-cv with --ard: the folds choose trainbr's epochs without the ARD stage, so the
// held-out curve is the one without ARD.
TEST(Ard, CrossValidatedStoppingIgnoresTheArdStage) {
  const ProcessTable table = synth::SyntheticProcessTable(20, 0.05, 6);
  ModelTrainOptions o = DefaultTrainingOptions();
  o.threads = 1;
  o.train.epochs = 40;
  std::vector<double> plain, ard;
  const int e_plain = ChooseEpochsByCrossValidation(table, o, 4, &plain);
  o.train.ard = true;
  const int e_ard = ChooseEpochsByCrossValidation(table, o, 4, &ard);
  EXPECT_EQ(e_ard, e_plain);
  EXPECT_EQ(ard, plain);
  EXPECT_EQ(ard.size(), 40u);
}

}  // namespace
}  // namespace whirl::nn
