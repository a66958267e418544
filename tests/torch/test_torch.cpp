// LibTorch cross-check of the Eigen network. References: nn's analytic results (the
// thing under test from the other side), central finite differences, and the closed-form ridge
// regression minimum of a network without hidden layer. No number here comes from a previous run.
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <filesystem>
#include <iostream>
#include <vector>

#include "core/error.h"
#include "core/random.h"
#include "nn/model.h"
#include "nn/network.h"
#include "support/eigen_near.h"
#include "torch/crosscheck.h"
#include "torch/libtorch_network.h"
#include "torch_test_support.h"
#include "support/scratch_dir.h"

namespace whirl::torch {
namespace {

namespace fs = std::filesystem;
using test::AllNear;

const std::vector<std::vector<int>> kShapes = {{5, 6, 2}, {3, 4, 4, 2}, {1, 1}, {2, 3, 1}};

nn::Network RandomNetwork(const std::vector<int>& sizes, std::uint64_t seed) {
  nn::Network net = nn::Network::Zeros(sizes);
  nn::InitNguyenWidrow(seed, &net);
  return net;
}

Eigen::MatrixXd RandomMatrix(int rows, int cols, double lo, double hi, std::uint64_t seed) {
  Rng rng(seed);
  Eigen::MatrixXd m(rows, cols);
  for (int c = 0; c < cols; ++c)
    for (int r = 0; r < rows; ++r) m(r, c) = rng.Uniform(lo, hi);
  return m;
}

fs::path ScratchDir(const std::string& name) {
  const fs::path dir =
      whirl::test::ScratchDir() / ("whirl_torch_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

TEST(TorchNetwork, ForwardMatchesEigenOnRandomNetworks) {
  for (const auto& sizes : kShapes) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const nn::Network net = RandomNetwork(sizes, seed);
      const Eigen::MatrixXd x = RandomMatrix(sizes.front(), 7, -1.5, 1.5, 100 + seed);
      EXPECT_TRUE(AllNear(TorchForward(MakeLayout(net), net.GetParameters(), x), net.Forward(x),
                          1e-12, 1e-12))
          << "layers " << sizes.size() << " seed " << seed;
    }
  }
}

TEST(TorchNetwork, AutogradJacobianMatchesAnalyticAndFiniteDifferences) {
  for (const auto& sizes : kShapes) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      nn::Network net = RandomNetwork(sizes, seed);
      const Eigen::MatrixXd x = RandomMatrix(sizes.front(), 4, -1, 1, 200 + seed);
      const Eigen::VectorXd w = net.GetParameters();
      const Eigen::MatrixXd j_torch = TorchJacobian(MakeLayout(net), w, x);

      nn::ForwardCache cache;
      net.Forward(x, &cache);
      Eigen::MatrixXd j_eigen;
      nn::ErrorJacobian(net, cache, &j_eigen);
      EXPECT_TRUE(AllNear(j_torch, j_eigen, 1e-10, 1e-10));

      // Independent of both: central differences of e = t - y (t drops out), sample-major rows.
      Eigen::MatrixXd j_fd(j_torch.rows(), j_torch.cols());
      const double h = 1e-6;
      for (int i = 0; i < w.size(); ++i) {
        Eigen::VectorXd wp = w, wm = w;
        wp(i) += h;
        wm(i) -= h;
        net.SetParameters(wp);
        const Eigen::MatrixXd yp = net.Forward(x);
        net.SetParameters(wm);
        const Eigen::MatrixXd ym = net.Forward(x);
        const Eigen::MatrixXd d = -(yp - ym) / (2 * h);
        j_fd.col(i) = Eigen::Map<const Eigen::VectorXd>(d.data(), d.size());
      }
      net.SetParameters(w);
      EXPECT_TRUE(AllNear(j_torch, j_fd, 1e-6, 1e-7));
    }
  }
}

TEST(TorchNetwork, ObjectiveAndGradientMatchFiniteDifferences) {
  const double alpha = 0.03, beta = 2.5;
  for (const auto& sizes : kShapes) {
    nn::Network net = RandomNetwork(sizes, 11);
    const Eigen::MatrixXd x = RandomMatrix(sizes.front(), 6, -1, 1, 301);
    const Eigen::MatrixXd t = RandomMatrix(sizes.back(), 6, -1, 1, 302);
    const Eigen::VectorXd w = net.GetParameters();
    const auto f_eigen = [&](const Eigen::VectorXd& v) {
      net.SetParameters(v);
      return beta * (t - net.Forward(x)).squaredNorm() + alpha * v.squaredNorm();
    };
    const TorchObjective obj = TorchEvaluate(MakeLayout(net), w, x, t, alpha, beta);
    EXPECT_NEAR(obj.objective, f_eigen(w), 1e-12 * std::abs(f_eigen(w)));
    EXPECT_NEAR(obj.sum_squared_weights, w.squaredNorm(), 1e-12 * w.squaredNorm());
    Eigen::VectorXd g_fd(w.size());
    for (int i = 0; i < w.size(); ++i) {
      Eigen::VectorXd wp = w, wm = w;
      wp(i) += 1e-6;
      wm(i) -= 1e-6;
      g_fd(i) = (f_eigen(wp) - f_eigen(wm)) / 2e-6;
    }
    EXPECT_TRUE(AllNear(obj.gradient, g_fd, 1e-6, 1e-6));
  }
}

TEST(TorchNetwork, ComparisonIsSensitiveToTheWeightOrder) {
  // Swapping two flat indices must show up as a large Jacobian difference: the figure can fail.
  const nn::Network net = RandomNetwork({5, 6, 2}, 4);
  const Eigen::MatrixXd x = RandomMatrix(5, 5, -1, 1, 401);
  FlatLayout wrong = MakeLayout(net);
  std::swap(wrong.weight_index[0](0, 0), wrong.weight_index[0](1, 0));
  nn::ForwardCache cache;
  net.Forward(x, &cache);
  Eigen::MatrixXd j_eigen;
  nn::ErrorJacobian(net, cache, &j_eigen);
  const Eigen::MatrixXd j_wrong = TorchJacobian(wrong, net.GetParameters(), x);
  EXPECT_GT((j_wrong - j_eigen).cwiseAbs().maxCoeff(), 1e-3);
}

TEST(TorchNetwork, LayoutRejectsDuplicateIndices) {
  FlatLayout layout = MakeLayout(RandomNetwork({2, 3, 1}, 1));
  layout.bias_index[1](0) = layout.bias_index[0](0);
  EXPECT_THROW(layout.Validate(), InputError);
  EXPECT_THROW(TorchForward(layout, Eigen::VectorXd::Zero(layout.parameter_count),
                            Eigen::MatrixXd::Zero(2, 1)),
               InputError);
}

TEST(TorchTraining, BothMinimisersReachTheClosedFormRidgeSolution) {
  // A network without hidden layer is linear: F = beta |T - W X - b|^2 + alpha (|W|^2 + |b|^2) is
  // ridge regression with the closed-form minimum theta_k = (beta Xa Xa' + alpha I)^-1 beta Xa t_k,
  // Xa = [X; 1'], per output k.
  const double alpha = 0.2, beta = 3.0;
  const nn::Network start = RandomNetwork({3, 2}, 5);
  const Eigen::MatrixXd x = RandomMatrix(3, 12, -1, 1, 501);
  const Eigen::MatrixXd t = RandomMatrix(2, 12, -1, 1, 502);
  Eigen::MatrixXd xa(4, 12);
  xa << x, Eigen::RowVectorXd::Ones(12);
  const Eigen::MatrixXd a = beta * xa * xa.transpose() + alpha * Eigen::MatrixXd::Identity(4, 4);
  nn::Network best = start;
  for (int k = 0; k < 2; ++k) {
    const Eigen::VectorXd theta = a.ldlt().solve(beta * xa * t.row(k).transpose());
    best.weights[0].row(k) = theta.head(3).transpose();
    best.biases[0](k) = theta(3);
  }
  const Eigen::VectorXd w_best = best.GetParameters();
  const double f_best = beta * (t - best.Forward(x)).squaredNorm() + alpha * w_best.squaredNorm();

  const GaussNewtonSummary gn = MinimizeFixedHyperparameters(start, x, t, alpha, beta);
  EXPECT_TRUE(gn.Converged()) << gn.BriefReport();
  EXPECT_NEAR(gn.final_objective, f_best, 1e-10 * f_best);
  EXPECT_TRUE(AllNear(gn.w, w_best, 1e-8, 1e-9));

  const LbfgsSummary lb =
      TorchMinimize(MakeLayout(start), start.GetParameters(), x, t, alpha, beta);
  EXPECT_TRUE(lb.Converged()) << lb.BriefReport();
  EXPECT_NEAR(lb.final_objective, f_best, 1e-10 * f_best);
  // LBFGS resolves the gradient only down to what F can show in floating point; F is strongly
  // convex with Hessian >= 2 alpha I, so |w - w*| <= |dF/dw(w)| / (2 alpha).
  const double g_norm = TorchEvaluate(MakeLayout(start), lb.w, x, t, alpha, beta).gradient.norm();
  EXPECT_LE((lb.w - w_best).norm(), g_norm / (2 * alpha) + 1e-12);
  EXPECT_LE(g_norm, 1e-6);
  EXPECT_LT(lb.final_objective, lb.initial_objective);
}

TEST(TorchCrosscheck, TrainedModelPassesEveryFigure) {
  const nn::Model model = test::SmallTrainedModel();
  const CrosscheckReport report = RunCrosscheck(model, test::SyntheticTable(20, 7));
  std::cout << report.Table() << report.BriefReport() << "\n";
  ASSERT_EQ(report.figures.size(), 7u);
  for (const auto& f : report.figures) {
    EXPECT_TRUE(f.Passed()) << f.name << " = " << f.value << " > " << f.tolerance;
  }
  EXPECT_TRUE(report.eigen_training.Converged()) << report.eigen_training.BriefReport();
  EXPECT_TRUE(report.torch_training.Converged()) << report.torch_training.BriefReport();
  // Both descended from the same start.
  EXPECT_NEAR(report.torch_training.initial_objective, report.eigen_training.initial_objective,
              1e-12 * report.eigen_training.initial_objective);
  EXPECT_LT(report.eigen_training.final_objective, report.eigen_training.initial_objective);
  EXPECT_TRUE(report.Passed());
  const nlohmann::json j = report;
  EXPECT_EQ(j.at("passed"), true);
  EXPECT_EQ(j.at("figures").size(), 7u);
}

TEST(TorchCrosscheck, TrainingAgreesFromSeveralStartsAndSizes) {
  // Property over starts and architectures: both minimisers reach the same minimum.
  const ProcessTable table = test::SyntheticTable(20, 7);
  for (const std::vector<int>& hidden : {std::vector<int>{4}, std::vector<int>{3, 3}}) {
    nn::ModelTrainOptions train;
    train.hidden_sizes = hidden;
    train.seed = 5;
    train.train.epochs = 300;
    train.stopping = nn::Stopping::kTrainbrMatlab;  // cross-checked against MATLAB trainbr
    const nn::Model model = nn::TrainModel(table, train, "synthetic");
    for (std::uint64_t seed : {2u, 3u}) {
      CrosscheckOptions options;
      options.seed = seed;
      const CrosscheckReport report = RunCrosscheck(model, table, options);
      EXPECT_TRUE(report.Passed()) << "hidden layers " << hidden.size() << ", seed " << seed << "\n"
                                   << report.Table();
    }
  }
}

TEST(TorchCrosscheck, RejectsBadOptionsAndData) {
  const nn::Model model = test::SmallTrainedModel();
  CrosscheckOptions bad;
  bad.start_perturbation = 2;
  EXPECT_THROW(RunCrosscheck(model, test::SyntheticTable(3, 1), bad), InputError);
  ProcessTable no_targets = test::SyntheticTable(3, 1);
  no_targets.targets.clear();
  EXPECT_THROW(RunCrosscheck(model, no_targets), InputError);
  EXPECT_THROW(RunCrosscheck(model, Eigen::MatrixXd::Zero(4, 3), Eigen::MatrixXd::Zero(2, 3)),
               InputError);
}

TEST(TorchExport, LoadedTorchScriptPredictsLikeTheEigenModel) {
  const nn::Model model = test::SmallTrainedModel();
  const fs::path dir = ScratchDir("export");
  const fs::path file = dir / "model.pt";
  const ExportReport report = ExportTorchScript(model, file);
  ASSERT_TRUE(report.written);
  EXPECT_LE(report.max_relative_difference, 1e-12);
  ASSERT_TRUE(fs::exists(file));
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);

  // Fresh inputs inside and somewhat outside the training domain, original units.
  Rng rng(77);
  std::vector<ProcessInputs> inputs;
  for (int q = 0; q < 40; ++q) {
    inputs.push_back({rng.Uniform(58, 67), rng.Uniform(40, 110), rng.Uniform(5, 18),
                      rng.Uniform(2, 11), rng.Uniform(140, 220)});
  }
  const Eigen::MatrixXd y_script = RunTorchScript(file, nn::InputMatrix(inputs));
  std::vector<Features> means;
  for (const auto& p : nn::PredictBatch(model, inputs)) means.push_back(p.mean);
  EXPECT_TRUE(AllNear(y_script, nn::TargetMatrix(means), 1e-12));

  // One sample as a 1-D tensor gives a 1-D result; a wrong input width is refused.
  const Eigen::VectorXd one = RunTorchScriptOne(file, nn::InputMatrix({inputs[3]}).col(0));
  EXPECT_TRUE(AllNear(one, nn::TargetMatrix({means[3]}).col(0), 1e-12));
  EXPECT_THROW(RunTorchScript(file, Eigen::MatrixXd::Ones(4, 2)), InputError);

  const auto in_names = TorchScriptNames(file, true);
  const auto out_names = TorchScriptNames(file, false);
  ASSERT_EQ(in_names.size(), 5u);
  ASSERT_EQ(out_names.size(), 2u);
  for (int i = 0; i < 5; ++i) EXPECT_EQ(in_names[i], kInputColumns[i]);
  for (int i = 0; i < 2; ++i) EXPECT_EQ(out_names[i], kTargetColumns[i]);
  fs::remove_all(dir);
}

TEST(TorchExport, ConstantVariablesPassThroughLikeMapMinMax) {
  // mapminmax passes a constant variable through unchanged; the LibTorch module and the exported
  // script must do the same (input 1 and target 0 constant here).
  const nn::Network net = RandomNetwork({3, 4, 2}, 9);
  ModelSpec spec;
  spec.layout = MakeLayout(net);
  spec.w = net.GetParameters();
  nn::MapMinMax in_scale{Eigen::Vector3d(1, 5, -2), Eigen::Vector3d(3, 5, 4)};
  nn::MapMinMax out_scale{Eigen::Vector2d(7, 10), Eigen::Vector2d(7, 30)};
  spec.input_min = in_scale.xmin;
  spec.input_max = in_scale.xmax;
  spec.target_min = out_scale.xmin;
  spec.target_max = out_scale.xmax;
  spec.input_names = {"a", "b", "c"};
  spec.target_names = {"u", "v"};
  const Eigen::MatrixXd x = RandomMatrix(3, 6, -3, 6, 601);
  const Eigen::MatrixXd expected = out_scale.Reverse(net.Forward(in_scale.Apply(x)));
  EXPECT_TRUE(AllNear(TorchPredictRaw(spec, x), expected, 1e-12, 1e-13));
  const fs::path dir = ScratchDir("constant");
  SaveTorchScript(dir / "c.pt", spec);
  EXPECT_TRUE(AllNear(RunTorchScript(dir / "c.pt", x), expected, 1e-12, 1e-13));
  fs::remove_all(dir);
}

TEST(TorchExport, BadPathsAreInputErrorsAndLeaveNoFile) {
  const nn::Model model = test::SmallTrainedModel();
  const fs::path dir = ScratchDir("badpath");
  EXPECT_THROW(ExportTorchScript(model, dir / "missing" / "m.pt"), InputError);
  EXPECT_THROW(RunTorchScript(dir / "absent.pt", Eigen::MatrixXd::Zero(5, 1)), InputError);
  // A file that is not TorchScript.
  {
    std::FILE* f = std::fopen((dir / "junk.pt").c_str(), "w");
    std::fputs("not a zip archive", f);
    std::fclose(f);
  }
  EXPECT_THROW(RunTorchScript(dir / "junk.pt", Eigen::MatrixXd::Zero(5, 1)), InputError);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace whirl::torch
