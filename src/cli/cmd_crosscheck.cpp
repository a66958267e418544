// whirl crosscheck: the Eigen network against an independent LibTorch implementation.
// Compiled into build/whirl-torch only (the one whirl executable that links LibTorch);
// build/whirl forwards "whirl crosscheck ..." to it (cli/torch_forward.cpp).
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/error.h"
#include "core/process.h"
#include "nn/model.h"
#include "workpiece/model.h"
#include "torch/crosscheck.h"

namespace whirl::cli {
namespace {

struct CrosscheckCliOptions {
  std::string model_path;
  std::string data_path;
  bool json = false;
  double alpha = 0;
  double beta = 0;
  double perturbation = 0.1;
  std::uint64_t seed = 1;
  double prediction_tolerance = 1e-5;
};

void RunCrosscheck(const CrosscheckCliOptions& o) {
  const nn::Model model = workpiece::LoadNetworkModel(o.model_path, "crosscheck");
  const ProcessTable table = ReadProcessTable(o.data_path, /*require_targets=*/true);
  torch::CrosscheckOptions options;
  options.alpha = o.alpha;
  options.beta = o.beta;
  options.start_perturbation = o.perturbation;
  options.seed = o.seed;
  options.training_prediction_tolerance = o.prediction_tolerance;
  const torch::CrosscheckReport report = torch::RunCrosscheck(model, table, options);
  if (o.json) {
    nlohmann::json j = report;
    j["model"] = o.model_path;
    j["data"] = o.data_path;
    PrintJson(j);
  } else {
    std::printf("model %s, data %s\n%s%s\n", o.model_path.c_str(), o.data_path.c_str(),
                report.Table().c_str(), report.BriefReport().c_str());
  }
  if (!report.Passed()) throw CommandFailure(report.BriefReport(), 2);
}

}  // namespace

void RegisterCrosscheck(CLI::App& app) {
  auto o = std::make_shared<CrosscheckCliOptions>();
  auto* sub = app.add_subcommand(
      "crosscheck",
      "Check the Eigen network against an independent LibTorch implementation (float64, "
      "autograd).\n"
      "Compares, on the table's samples: forward outputs (normalized network and whole model in\n"
      "original units, tolerance 1e-12 relative), the error Jacobian J = de/dw (autograd vs "
      "analytic,\n"
      "1e-10 relative to max|J|), the trainbr objective F = beta*ssE + alpha*ssX (1e-12 relative) "
      "and\n"
      "its gradient (1e-10), and training: from the same start (model weights perturbed by\n"
      "--perturbation) with alpha, beta fixed, the Eigen damped Gauss-Newton (trainbr LM loop on "
      "nn's\n"
      "Jacobian) and LibTorch LBFGS (strong Wolfe, Gauss-Newton preconditioned with an autograd\n"
      "Jacobian) must reach the same minimum (F within 1e-6 relative, predictions within\n"
      "--prediction-tolerance normalized target units). Use the model's training table: on other\n"
      "data, with the model's alpha, beta, the two may legitimately find different local minima.\n"
      "Errors are measured in the model's normalized (mapminmax) target space.\n"
      "Exit code 0 when every figure is within tolerance, 2 when one is not, 1 on bad input.");
  sub->add_option("--model", o->model_path, "Model file (JSON, written by 'whirl train')")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--data", o->data_path,
                  "Process table (CSV) with the five input and two target columns "
                  "(hardness_hrc, diameter_mm, pitch_mm, raceway_radius_mm, cutting_speed_m_min, "
                  "max_elongation_um, settle_time_s), e.g. the training table")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_flag("--json", o->json, "Machine output: the report as JSON on stdout");
  sub->add_option("--alpha", o->alpha,
                  "Weight-decay coefficient alpha of F (MATLAB convention, dimensionless); "
                  "default: the model's final trainbr value")
      ->check(PositiveNumber());
  sub->add_option("--beta", o->beta,
                  "Data coefficient beta of F (1/normalized unit^2); default: the model's final "
                  "trainbr value")
      ->check(PositiveNumber());
  sub->add_option("--perturbation", o->perturbation,
                  "Relative perturbation of the model weights for the common training start: "
                  "w0 = w .* (1 + p*u), u ~ U(-1, 1)")
      ->check(NumberIn(0.0, 1.0))
      ->capture_default_str();
  AddSeedOption(sub, &o->seed, "Seed of the start perturbation")->capture_default_str();
  sub->add_option("--prediction-tolerance", o->prediction_tolerance,
                  "Tolerance of the trained-prediction difference, normalized target units (the "
                  "training range of a target spans 2 units)")
      ->check(PositiveNumber())
      ->capture_default_str();
  sub->callback([o] { RunCrosscheck(*o); });
}

}  // namespace whirl::cli
