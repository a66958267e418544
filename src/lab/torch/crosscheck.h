#pragma once
// Cross-check of the Eigen network (nn/) against the independent LibTorch implementation
// (libtorch_network.h), and the TorchScript export of a model. Torch-free header: the whirl
// commands include this file only.
//
// What is compared (STYLE.md 8: outputs, not weights), all on the same data and weights:
//   forward     max_ij |y_T - y_E| / max(|y_E|, 1) in the normalized output space (the network),
//   and
//               max_ij |y_T - y_E| / |y_E| in original units (the whole model, scaling included:
//               nn::Predict versus the LibTorch torch::nn::Module with mapminmax buffers);
//   jacobian    max_ij |J_T - J_E| / max(1, max_ij |J_E|), J = de/dw (n x N), autograd versus nn's
//               analytic back-propagation (nn::ErrorJacobian);
//   objective   |F_T - F_E| / |F_E|, F = beta ssE + alpha ssX (MacKay 1992; trainbr.h);
//   gradient    max_i |g_T - g_E|_i / max_i (2 beta |J|'(|t| + |y|) + 2 alpha |w|)_i, g = dF/dw;
//               the Eigen side is g_E = 2 (beta J'e + alpha w) from nn's Jacobian; the scale is the
//               sum of magnitudes of the terms (meaningful at a minimum where g ~ 0) with |t| + |y|
//               for |e| because e = t - y cancels on a close fit: there two correct codes differ
//               by ~eps |y| per error, and with beta ~ 1e8 that alone is ~1e-9 of 2 beta |J|'|e|;
//   training    from the same start w0 with alpha, beta fixed, F minimised (a) in Eigen by the
//               damped Gauss-Newton (Levenberg-Marquardt) iteration of trainbr on nn's Jacobian,
//               (b) in LibTorch by torch::optim::LBFGS with strong-Wolfe line search on autograd
//               gradients (Gauss-Newton preconditioned by default, see TorchMinimize). Agreement:
//               |F_a - F_b| / |F_a| and the largest difference of the two trained networks'
//               predictions on the data, normalized target units (a range of the training targets
//               is 2 units, so 1e-6 units is 5e-7 of the range).
// The objective and gradient are evaluated at the model's weights and at w0; the worse is reported.
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/process.h"
#include "nn/model.h"
#include "nn/network.h"
#include "torch/libtorch_network.h"

namespace whirl::torch {

/// nn's flat order (Network::BiasIndex / WeightIndex, errors sample-major) as a FlatLayout.
FlatLayout MakeLayout(const nn::Network& net);

/// The model (weights, mapminmax scaling, names) in the form libtorch_network.h takes.
ModelSpec MakeModelSpec(const nn::Model& model, const std::string& description = "");

/// Eigen-side minimiser of F(w) = beta ssE + alpha ssX with alpha, beta FIXED: the LM loop of
/// trainbr (trainbr.h step 3) without the alpha/beta update,
///   dw = -(beta J'J + (mu + alpha) I)^-1 (beta J'e + alpha w),
/// accept if F(w + dw) < F(w) (mu *= mu_dec, floor 1e-20), else mu *= mu_inc.
struct GaussNewtonOptions {
  int max_iterations = 5000;  ///< accepted-or-failed LM loops
  double gradient_tolerance =
      1e-10;             ///< stop when ||dF/dw||_inf <= this (dF/dw = 2(beta J'e + alpha w))
  double mu = 0.005;     ///< initial damping (trainbr default)
  double mu_dec = 0.1;   ///< after an accepted step
  double mu_inc = 10.0;  ///< after a rejected step
  double mu_max = 1e10;  ///< give up when no damping lowers F any more
};

enum class GaussNewtonTermination {
  kGradientTolerance,  ///< converged
  kMaxMu,              ///< F cannot be lowered in floating point any more: converged to rounding
  kMaxIterations,      ///< not converged
};
std::string ToString(GaussNewtonTermination t);

struct GaussNewtonSummary {
  double initial_objective = 0;
  double final_objective = 0;
  double final_gradient_inf = 0;  ///< ||dF/dw||_inf at the returned weights
  int iterations = 0;
  GaussNewtonTermination termination = GaussNewtonTermination::kMaxIterations;
  std::string message;  ///< the compared numbers
  Eigen::VectorXd w;    ///< final weights, nn flat order

  bool Converged() const { return termination != GaussNewtonTermination::kMaxIterations; }
  /// "Gauss-Newton (Eigen, nn Jacobian): F 3.2 -> 1.1 in 40 iterations, gradient_tolerance (...)".
  std::string BriefReport() const;
};

/// Minimises F from `start` on normalized data x (R x Q), t (S x Q). InputError on bad sizes or
/// options; non-convergence is a Summary outcome.
GaussNewtonSummary MinimizeFixedHyperparameters(const nn::Network& start, const Eigen::MatrixXd& x,
                                                const Eigen::MatrixXd& t, double alpha, double beta,
                                                const GaussNewtonOptions& options = {});

struct CrosscheckOptions {
  /// Tolerances of the five figures (definitions at the top of this file).
  double forward_tolerance = 1e-12;             ///< relative
  double jacobian_tolerance = 1e-10;            ///< relative to max |J|
  double objective_tolerance = 1e-12;           ///< relative
  double gradient_tolerance = 1e-10;            ///< relative to the term magnitudes
  double training_objective_tolerance = 1e-6;   ///< relative
  double training_prediction_tolerance = 1e-5;  ///< normalized target units (stated in the report)
  /// alpha, beta of F; <= 0 means: the model's final trainbr values (TrainSummary alpha, beta).
  /// A model trained with --ard (TrainSummary::ard_alpha) is checked with one alpha, the group
  /// of all weights but the first layer's (its TrainSummary alpha): the cross-check covers the
  /// network, its Jacobian and trainbr's objective, not ARD's per-input groups.
  double alpha = 0;
  double beta = 0;
  /// Start of both trainings: w0 = w_model .* (1 + p u), u ~ uniform(-1, 1) from Rng(seed),
  /// p = start_perturbation (0 starts at the model's weights). Both minimisers then descend into
  /// the same basin; from a random start they may legitimately find different local minima.
  double start_perturbation = 0.1;
  std::uint64_t seed = 1;
  GaussNewtonOptions eigen_training;
  LbfgsOptions torch_training;

  /// InputError naming the option, value and rule.
  void Validate() const;
};

/// One row of the cross-check table.
struct CrosscheckFigure {
  std::string name;  ///< "forward", "forward_original_units", "jacobian", ...
  double value = 0;  ///< the measured difference
  double tolerance = 0;
  std::string definition;                             ///< how `value` is measured
  bool Passed() const { return value <= tolerance; }  // NaN fails
};
void to_json(nlohmann::json& j, const CrosscheckFigure& f);

struct CrosscheckReport {
  std::string torch_version;
  int sample_count = 0;     ///< Q
  int parameter_count = 0;  ///< N
  double alpha = 0, beta = 0;
  std::vector<CrosscheckFigure> figures;
  GaussNewtonSummary eigen_training;
  LbfgsSummary torch_training;

  bool Passed() const;
  /// The table: name, value, tolerance, pass/FAIL, definition; then the two training reports.
  std::string Table() const;
  /// "crosscheck: 7/7 figures within tolerance (worst: training_objective 3e-9 <= 1e-6)".
  std::string BriefReport() const;
};
void to_json(nlohmann::json& j, const CrosscheckReport& r);

/// Runs every comparison for `model` on raw (original-unit) inputs (R x Q) and targets (S x Q).
/// InputError on inconsistent sizes or non-finite values; disagreement is a report outcome.
CrosscheckReport RunCrosscheck(const nn::Model& model, const Eigen::MatrixXd& inputs_raw,
                               const Eigen::MatrixXd& targets_raw,
                               const CrosscheckOptions& options = {});

/// Same, on a process table with targets (ReadProcessTable(path, true)).
CrosscheckReport RunCrosscheck(const nn::Model& model, const ProcessTable& table,
                               const CrosscheckOptions& options = {});

struct ExportOptions {
  /// Points where the written file is compared with nn::Predict, raw inputs (R x Q, original
  /// units); empty: the 2^R corners of the model's training domain and its centre.
  Eigen::MatrixXd check_inputs_raw;
  /// Largest accepted max |y_script - y_eigen| / |y_eigen| (original units).
  double tolerance = 1e-12;
  /// Provenance stored in the module (description()).
  std::string description;
};

struct ExportReport {
  std::string path;
  bool written = false;  ///< false when the check failed (no file is left behind)
  int check_points = 0;
  double max_relative_difference = 0;  ///< max |y_script - y_eigen| / |y_eigen|, original units
  double tolerance = 0;
  std::vector<std::string> input_names, target_names;                   ///< as stored in the file
  bool Passed() const { return max_relative_difference <= tolerance; }  // NaN fails
};
void to_json(nlohmann::json& j, const ExportReport& r);

/// Exports `model` as TorchScript (see SaveTorchScript for the module's methods): writes a
/// temporary file in the target directory, loads it back with torch::jit::load, compares its
/// forward() on the check points with nn::Predict and renames it to `path` only if the
/// difference is within tolerance. InputError on unwritable paths or a bad model.
ExportReport ExportTorchScript(const nn::Model& model, const std::filesystem::path& path,
                               const ExportOptions& options = {});

}  // namespace whirl::torch
