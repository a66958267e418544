#pragma once
// The network of nn/network.h re-implemented independently in LibTorch (double precision), plus
// its TorchScript export. This header is torch-free on purpose: only libtorch_network.cpp includes
// torch/torch.h (it is the single slow translation unit; see docs/network.md), every other file
// talks to LibTorch through the plain Eigen/std types declared here.
//
// Conventions shared with nn (MATLAB's trainbr, nn/trainbr.h):
//   - a network is layers l = 0..L-1 with weights W_l (rows = outputs of layer l) and biases b_l,
//     tansig (tanh) on every hidden layer, linear output layer;
//   - inputs and outputs here are in the normalized (mapminmax, [-1, 1]) space, one sample per
//     column, exactly as nn's forward pass;
//   - errors e = t - y; their flattened order and the flattened weight order are nn's, described to
//     this file by a FlatLayout (built from nn's own flatten function, so no order is assumed
//     here);
//   - objective F(w) = beta * ssE + alpha * ssX, ssE = sum e^2, ssX = w'w (MacKay 1992, eq. 2.1;
//     Foresee & Hagan 1997).
// Autograd (reverse mode) provides the Jacobian and gradient: an implementation that shares no code
// with nn's analytic back-propagation.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace whirl::torch {

/// Where each weight and bias sits in nn's flat parameter vector, and how errors are flattened.
struct FlatLayout {
  std::vector<int> layer_sizes;               ///< e.g. {5, 6, 2}
  std::vector<Eigen::MatrixXi> weight_index;  ///< weight_index[l](r, c) = flat index of W_l(r, c)
  std::vector<Eigen::VectorXi> bias_index;    ///< bias_index[l](r) = flat index of b_l(r)
  int parameter_count = 0;                    ///< N, e.g. 50 for 5-6-2
  /// Flat error index of (output k, sample q) for Q samples: sample-major means q * outputs + k
  /// (column-major flattening of the outputs x Q error matrix); otherwise k * Q + q.
  bool errors_sample_major = true;

  int ErrorIndex(int k, int q, int sample_count) const {
    const int outputs = layer_sizes.back();
    return errors_sample_major ? q * outputs + k : k * sample_count + q;
  }
  /// Throws InputError if the indices are not a permutation of 0..N-1 or shapes disagree.
  void Validate() const;
};

/// Forward pass y = f(x; w) by LibTorch; x_norm (inputs x Q), returns outputs x Q.
Eigen::MatrixXd TorchForward(const FlatLayout& layout, const Eigen::VectorXd& w,
                             const Eigen::MatrixXd& x_norm);

/// J_e_w (n x N, n = outputs * Q, rows in the layout's error order) of e = t - y by reverse-mode
/// autograd, one backward pass per error row. Does not depend on t (de/dw = -dy/dw).
Eigen::MatrixXd TorchJacobian(const FlatLayout& layout, const Eigen::VectorXd& w,
                              const Eigen::MatrixXd& x_norm);

/// F = beta ssE + alpha ssX and its gradient dF/dw (size N, flat order) by autograd.
struct TorchObjective {
  double objective = 0;            ///< F
  double sum_squared_errors = 0;   ///< ssE
  double sum_squared_weights = 0;  ///< ssX
  Eigen::VectorXd gradient;        ///< dF/dw
};
TorchObjective TorchEvaluate(const FlatLayout& layout, const Eigen::VectorXd& w,
                             const Eigen::MatrixXd& x_norm, const Eigen::MatrixXd& t_norm,
                             double alpha, double beta);

/// LibTorch torch::optim::LBFGS with strong-Wolfe line search on F(w), alpha and beta fixed.
/// With beta ~ 1e8 (near noise-free data) F is so ill-conditioned that plain LBFGS stalls far from
/// the minimum; the default therefore runs each step in preconditioned variables
/// w = w_c + M z, M = L^-T, L L' = beta J'J + alpha I (J = dy/dw by autograd at the step's start
/// w_c, Cholesky by torch::linalg): the same F and minima, Hessian ~ 2 I near w_c (Nocedal &
/// Wright, Numerical Optimization, 2nd ed., section 7.2 on preconditioned quasi-Newton). A fresh
/// LBFGS (history cleared) runs in each step; if H is not positive definite (alpha = 0 and rank
/// deficient J) that step falls back to plain LBFGS.
struct LbfgsOptions {
  /// Outer calls of LBFGS::step; each runs up to `iterations_per_step` LBFGS iterations.
  int max_steps = 100;
  int iterations_per_step = 100;
  /// LBFGS history (number of correction pairs). On the 5-6-2 cross-check 30 reached the
  /// minimum in about 4x fewer evaluations than 10 or 100 (and to a smaller gradient).
  int history_size = 30;
  /// Stop when ||dF/dw||_inf <= gradient_tolerance (torch's tolerance_grad, same norm).
  double gradient_tolerance = 1e-10;
  /// torch's tolerance_change: stop inside a step when F or the step changes less than this.
  double change_tolerance = 1e-16;
  /// Gauss-Newton preconditioner refreshed at every step (see above); false = plain LBFGS with
  /// one history over all steps.
  bool gauss_newton_preconditioner = true;
};

enum class LbfgsTermination {
  kGradientTolerance,  ///< ||dF/dw||_inf <= gradient_tolerance: converged
  /// A whole step left F unchanged: the strong-Wolfe line search finds no lower F in floating
  /// point. Near a minimum this is convergence to rounding (|g| ~ sqrt(eps F H) cannot be resolved
  /// through F), elsewhere a stall; the cross-check figures tell which.
  kNoProgress,
  kMaxSteps,   ///< step limit reached: not converged
  kNonFinite,  ///< F or its gradient became NaN/inf: failed
};
std::string ToString(LbfgsTermination t);

struct LbfgsSummary {
  double initial_objective = 0;
  double final_objective = 0;
  double final_gradient_inf = 0;  ///< ||dF/dw||_inf at the returned weights
  int steps = 0;                  ///< LBFGS::step calls
  int iterations = 0;             ///< LBFGS iterations over all steps (torch's n_iter)
  int function_evaluations = 0;   ///< objective+gradient evaluations (closure calls)
  bool preconditioned = false;    ///< LbfgsOptions::gauss_newton_preconditioner was on
  LbfgsTermination termination = LbfgsTermination::kMaxSteps;
  std::string message;  ///< the compared numbers
  Eigen::VectorXd w;    ///< final weights, flat order

  /// Gradient tolerance met, or no lower F representable (kNoProgress).
  bool Converged() const {
    return termination == LbfgsTermination::kGradientTolerance ||
           termination == LbfgsTermination::kNoProgress;
  }
  /// "LBFGS: F 12.3 -> 4.5 in 57 iterations (3 steps), gradient_tolerance (...)".
  std::string BriefReport() const;
};
LbfgsSummary TorchMinimize(const FlatLayout& layout, const Eigen::VectorXd& w0,
                           const Eigen::MatrixXd& x_norm, const Eigen::MatrixXd& t_norm,
                           double alpha, double beta, const LbfgsOptions& options = {});

/// A whole model as LibTorch sees it (built from an nn::Model by crosscheck.h MakeModelSpec):
/// weights in the layout's flat order and the mapminmax scaling of inputs and targets (nn: y = 2 (x
/// - xmin)/(xmax - xmin) - 1, a constant variable, xmax == xmin, passes through unchanged).
struct ModelSpec {
  FlatLayout layout;
  Eigen::VectorXd w;
  Eigen::VectorXd input_min, input_max;    ///< per input, original units
  Eigen::VectorXd target_min, target_max;  ///< per output, original units
  std::vector<std::string> input_names;    ///< column names with units, e.g. "hardness_hrc"
  std::vector<std::string> target_names;   ///< e.g. "max_elongation_um"
  std::string description;                 ///< provenance text stored in the module
};

/// Builds a TorchScript module (torch::jit::Module with buffers and TorchScript methods, no
/// Python needed) and saves it atomically (temporary file in the same directory, then rename).
///   forward(x: Tensor[B, inputs] float64, original units) -> Tensor[B, outputs] original units
///   (a 1-D x of size `inputs` gives a 1-D result), input_names() -> List[str],
///   target_names() -> List[str], description() -> str.
void SaveTorchScript(const std::filesystem::path& path, const ModelSpec& spec);

/// The torch::nn::Module (weights and scaling as buffers) evaluated on raw inputs (inputs x Q,
/// original units); returns outputs x Q in original units. Same computation as the exported module.
Eigen::MatrixXd TorchPredictRaw(const ModelSpec& spec, const Eigen::MatrixXd& x_raw);

/// Loads a TorchScript file and runs forward on raw inputs (inputs x Q, original units); returns
/// outputs x Q in original units. Throws InputError if the file cannot be loaded or run.
Eigen::MatrixXd RunTorchScript(const std::filesystem::path& path, const Eigen::MatrixXd& x_raw);

/// Same for one sample passed as a 1-D tensor of size `inputs` (the script returns a 1-D result).
Eigen::VectorXd RunTorchScriptOne(const std::filesystem::path& path, const Eigen::VectorXd& x_raw);

/// The names stored by SaveTorchScript (input_names(), target_names()).
std::vector<std::string> TorchScriptNames(const std::filesystem::path& path, bool inputs);

/// "LibTorch 1.13.1" (version the target was compiled against).
std::string TorchVersion();

}  // namespace whirl::torch
