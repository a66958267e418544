// The only translation unit of whirl that includes LibTorch headers: the few it uses rather than
// torch/torch.h (8 s instead of 11 s to compile; compile time: docs/network.md).
#include "torch/libtorch_network.h"

#include <torch/script.h>
#include <torch/optim/lbfgs.h>
#include <torch/nn/module.h>
#include <torch/linalg.h>
#include <torch/utils.h>
#include <torch/autograd.h>
#include <torch/version.h>

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/numbers.h"

// Torch helpers live outside namespace whirl::torch so that `torch::` never resolves to it.
namespace whirl_torch_detail {

using ::torch::Tensor;

const auto kF64 = ::torch::TensorOptions().dtype(::torch::kFloat64);

/// Eigen (column-major) matrix -> contiguous [rows, cols] float64 tensor (a copy).
Tensor ToTensor(const Eigen::MatrixXd& m) {
  Tensor t = ::torch::empty({m.rows(), m.cols()}, kF64);
  auto a = t.accessor<double, 2>();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) a[r][c] = m(r, c);
  return t;
}

Tensor ToTensor(const Eigen::VectorXd& v) {
  Tensor t = ::torch::empty({v.size()}, kF64);
  auto a = t.accessor<double, 1>();
  for (Eigen::Index i = 0; i < v.size(); ++i) a[i] = v(i);
  return t;
}

Eigen::MatrixXd ToEigenMatrix(const Tensor& t_in) {
  const Tensor t = t_in.detach().to(::torch::kFloat64).contiguous();
  if (t.dim() != 2) throw whirl::InputError("LibTorch: expected a 2-D tensor");
  Eigen::MatrixXd m(t.size(0), t.size(1));
  auto a = t.accessor<double, 2>();
  for (Eigen::Index r = 0; r < m.rows(); ++r)
    for (Eigen::Index c = 0; c < m.cols(); ++c) m(r, c) = a[r][c];
  return m;
}

/// One network, independent of nn's code: parameters per layer, samples as rows,
/// h_{l+1} = tanh(h_l W_l^T + b_l) on hidden layers, linear last layer. Scaling buffers make it the
/// whole model (mapminmax in, reverse mapminmax out).
class WhirlNetImpl : public ::torch::nn::Module {
 public:
  WhirlNetImpl(const whirl::torch::FlatLayout& layout, const Eigen::VectorXd& w) : layout_(layout) {
    layout_.Validate();
    if (w.size() != layout_.parameter_count) {
      throw whirl::InputError("LibTorch network: weight vector has " + std::to_string(w.size()) +
                              " entries, the layout needs " +
                              std::to_string(layout_.parameter_count));
    }
    const std::size_t layers = layout_.layer_sizes.size() - 1;
    for (std::size_t l = 0; l < layers; ++l) {
      const int rows = layout_.layer_sizes[l + 1], cols = layout_.layer_sizes[l];
      Eigen::MatrixXd wl(rows, cols);
      Eigen::VectorXd bl(rows);
      for (int r = 0; r < rows; ++r) {
        bl(r) = w(layout_.bias_index[l](r));
        for (int c = 0; c < cols; ++c) wl(r, c) = w(layout_.weight_index[l](r, c));
      }
      weights_.push_back(register_parameter("weight_" + std::to_string(l), ToTensor(wl)));
      biases_.push_back(register_parameter("bias_" + std::to_string(l), ToTensor(bl)));
    }
  }

  /// mapminmax buffers; a variable with max == min passes through unchanged (nn, MATLAB).
  void SetScaling(const Eigen::VectorXd& in_min, const Eigen::VectorXd& in_max,
                  const Eigen::VectorXd& out_min, const Eigen::VectorXd& out_max) {
    const auto add = [this](const std::string& name, const Eigen::VectorXd& lo,
                            const Eigen::VectorXd& hi) {
      Tensor min = ToTensor(lo);
      Tensor range = ToTensor(Eigen::VectorXd(hi - lo));
      Tensor constant = range.eq(0.0);
      register_buffer(name + "_min", min);
      // Safe range (1 where constant) keeps the unused branch of where() finite.
      register_buffer(name + "_range", ::torch::where(constant, ::torch::ones_like(range), range));
      register_buffer(name + "_constant", constant);
    };
    add("input", in_min, in_max);
    add("target", out_min, out_max);
  }

  Tensor ForwardNormalized(const Tensor& x) const { return ForwardWith(x, LayerParameters()); }

  /// The same network with other parameter values {W_0, b_0, W_1, b_1, ...} (may carry autograd
  /// history, e.g. functions of a preconditioned variable).
  static Tensor ForwardWith(const Tensor& x, const std::vector<Tensor>& p) {
    Tensor h = x;
    const std::size_t layers = p.size() / 2;
    for (std::size_t l = 0; l < layers; ++l) {
      h = ::torch::matmul(h, p[2 * l].t()) + p[2 * l + 1];
      if (l + 1 < layers) h = ::torch::tanh(h);
    }
    return h;
  }

  Tensor ForwardRaw(const Tensor& x) {
    const Tensor in_min = named_buffers()["input_min"], in_range = named_buffers()["input_range"];
    const Tensor in_const = named_buffers()["input_constant"];
    const Tensor out_min = named_buffers()["target_min"],
                 out_range = named_buffers()["target_range"];
    const Tensor out_const = named_buffers()["target_constant"];
    const Tensor xn = ::torch::where(in_const, x, 2.0 * (x - in_min) / in_range - 1.0);
    const Tensor y = ForwardNormalized(xn);
    return ::torch::where(out_const, y, (y + 1.0) * out_range / 2.0 + out_min);
  }

  std::vector<Tensor> LayerParameters() const {
    std::vector<Tensor> p;
    for (std::size_t l = 0; l < weights_.size(); ++l) {
      p.push_back(weights_[l]);
      p.push_back(biases_[l]);
    }
    return p;
  }

  /// Per-layer tensors (same order as LayerParameters) -> nn's flat order.
  Eigen::VectorXd Flatten(const std::vector<Tensor>& per_layer) const {
    Eigen::VectorXd flat = Eigen::VectorXd::Zero(layout_.parameter_count);
    for (std::size_t l = 0; l < weights_.size(); ++l) {
      const Eigen::MatrixXd wl = ToEigenMatrix(per_layer[2 * l]);
      const Eigen::MatrixXd bl = ToEigenMatrix(per_layer[2 * l + 1].reshape({-1, 1}));
      for (Eigen::Index r = 0; r < wl.rows(); ++r) {
        flat(layout_.bias_index[l](r)) = bl(r, 0);
        for (Eigen::Index c = 0; c < wl.cols(); ++c) flat(layout_.weight_index[l](r, c)) = wl(r, c);
      }
    }
    return flat;
  }

  const whirl::torch::FlatLayout& layout() const { return layout_; }

 private:
  whirl::torch::FlatLayout layout_;
  std::vector<Tensor> weights_, biases_;
};
TORCH_MODULE(WhirlNet);

/// Samples as rows for torch: Eigen (features x Q) -> tensor [Q, features].
Tensor SamplesToTensor(const Eigen::MatrixXd& x) {
  return ToTensor(Eigen::MatrixXd(x.transpose()));
}

Tensor ObjectiveWith(const std::vector<Tensor>& p, const Tensor& x, const Tensor& t, double alpha,
                     double beta, Tensor* sse, Tensor* ssx) {
  const Tensor e = t - WhirlNetImpl::ForwardWith(x, p);
  Tensor sum_e = e.pow(2).sum();
  Tensor sum_x = ::torch::zeros({}, kF64);
  for (const Tensor& q : p) sum_x = sum_x + q.pow(2).sum();
  if (sse != nullptr) *sse = sum_e;
  if (ssx != nullptr) *ssx = sum_x;
  return beta * sum_e + alpha * sum_x;
}

Tensor Objective(const WhirlNet& net, const Tensor& x, const Tensor& t, double alpha, double beta,
                 Tensor* sse, Tensor* ssx) {
  return ObjectiveWith(net->LayerParameters(), x, t, alpha, beta, sse, ssx);
}

/// Parameters as one vector in torch's own order (each tensor row-major, in LayerParameters order)
/// and back; used only inside the preconditioned LBFGS, never compared with nn's order.
Tensor CatParameters(const std::vector<Tensor>& p) {
  std::vector<Tensor> flat;
  for (const Tensor& q : p) flat.push_back(q.detach().reshape({-1}));
  return ::torch::cat(flat);
}

std::vector<Tensor> SplitParameters(const Tensor& v, const std::vector<Tensor>& like) {
  std::vector<Tensor> out;
  int64_t offset = 0;
  for (const Tensor& q : like) {
    out.push_back(v.narrow(0, offset, q.numel()).view(q.sizes()));
    offset += q.numel();
  }
  return out;
}

/// Gauss-Newton preconditioner M = L^-T with L L' = beta J'J + alpha I, J = dy/dw by autograd at
/// the current parameters (torch order). Undefined tensor if H is not positive definite.
Tensor GaussNewtonPreconditioner(const std::vector<Tensor>& params, const Tensor& x, double alpha,
                                 double beta) {
  const Tensor y = WhirlNetImpl::ForwardWith(x, params).reshape({-1});
  const int64_t n = y.size(0);
  int64_t count = 0;
  for (const Tensor& q : params) count += q.numel();
  Tensor jacobian = ::torch::zeros({n, count}, kF64);
  for (int64_t i = 0; i < n; ++i) {
    const std::vector<Tensor> g = ::torch::autograd::grad({y[i]}, params, {}, /*retain_graph=*/true,
                                                          /*create_graph=*/false,
                                                          /*allow_unused=*/true);
    std::vector<Tensor> filled;
    for (std::size_t k = 0; k < g.size(); ++k)
      filled.push_back(g[k].defined() ? g[k] : ::torch::zeros_like(params[k]));
    jacobian[i] = CatParameters(filled);
  }
  const Tensor eye = ::torch::eye(count, kF64);
  const Tensor h = beta * jacobian.t().mm(jacobian) + alpha * eye;
  try {
    const Tensor l = ::torch::linalg::cholesky(h);
    return ::torch::linalg::solve_triangular(l.t(), eye, /*upper=*/true, /*left=*/true,
                                             /*unitriangular=*/false);
  } catch (const c10::Error&) {
    return Tensor();
  }
}

void CheckData(const whirl::torch::FlatLayout& layout, const Eigen::MatrixXd& x,
               const Eigen::MatrixXd* t) {
  if (x.rows() != layout.layer_sizes.front()) {
    throw whirl::InputError("LibTorch network: inputs have " + std::to_string(x.rows()) +
                            " rows, the network takes " +
                            std::to_string(layout.layer_sizes.front()));
  }
  if (t != nullptr && (t->rows() != layout.layer_sizes.back() || t->cols() != x.cols())) {
    throw whirl::InputError("LibTorch network: targets are " + std::to_string(t->rows()) + "x" +
                            std::to_string(t->cols()) + ", expected " +
                            std::to_string(layout.layer_sizes.back()) + "x" +
                            std::to_string(x.cols()));
  }
}

/// Determinism: one thread (reductions in a fixed order), autograd on.
void Prepare() {
  static const bool once = [] {
    ::torch::set_num_threads(1);
    return true;
  }();
  (void)once;
}

/// TorchScript source of the exported module; layer count is spliced in, everything else is data.
std::string ScriptSource(int layers, int inputs) {
  std::ostringstream s;
  s << "def forward(self, x: Tensor) -> Tensor:\n"
    << "    one_sample = x.dim() == 1\n"
    << "    if one_sample:\n"
    << "        x = x.unsqueeze(0)\n"
    << "    assert x.dim() == 2 and x.size(1) == " << inputs
    << ", 'whirl model: expected inputs of shape [B, " << inputs
    << "] in original units (see input_names())'\n"
    << "    x = x.double()\n"
    << "    h = torch.where(self.input_constant, x, 2.0 * (x - self.input_min) / self.input_range"
       " - 1.0)\n";
  for (int l = 0; l < layers; ++l) {
    s << "    h = torch.matmul(h, self.weight_" << l << ".t()) + self.bias_" << l << "\n";
    if (l + 1 < layers) s << "    h = torch.tanh(h)\n";
  }
  s << "    y = torch.where(self.target_constant, h, (h + 1.0) * self.target_range / 2.0 +"
       " self.target_min)\n"
    << "    if one_sample:\n"
    << "        y = y.squeeze(0)\n"
    << "    return y\n"
    << "\n"
    << "def input_names(self) -> List[str]:\n"
    << "    return self.input_names_list\n"
    << "\n"
    << "def target_names(self) -> List[str]:\n"
    << "    return self.target_names_list\n"
    << "\n"
    << "def description(self) -> str:\n"
    << "    return self.description_text\n";
  return s.str();
}

WhirlNet MakeNet(const whirl::torch::ModelSpec& spec) {
  const int inputs = spec.layout.layer_sizes.front(), outputs = spec.layout.layer_sizes.back();
  if (spec.input_min.size() != inputs || spec.input_max.size() != inputs ||
      spec.target_min.size() != outputs || spec.target_max.size() != outputs) {
    throw whirl::InputError("LibTorch model: scaling vectors do not match the layer sizes");
  }
  WhirlNet net(spec.layout, spec.w);
  net->SetScaling(spec.input_min, spec.input_max, spec.target_min, spec.target_max);
  return net;
}

}  // namespace whirl_torch_detail

namespace whirl::torch {

using namespace whirl_torch_detail;  // NOLINT: helpers of this file only

void FlatLayout::Validate() const {
  if (layer_sizes.size() < 2) throw InputError("LibTorch layout: fewer than two layer sizes");
  const std::size_t layers = layer_sizes.size() - 1;
  if (weight_index.size() != layers || bias_index.size() != layers) {
    throw InputError("LibTorch layout: index tables do not match the number of layers");
  }
  std::vector<int> seen(static_cast<std::size_t>(std::max(parameter_count, 0)), 0);
  const auto mark = [&](int i) {
    if (i < 0 || i >= parameter_count || seen[static_cast<std::size_t>(i)]++ != 0) {
      throw InputError("LibTorch layout: flat index " + std::to_string(i) +
                       " is out of range or used twice (N = " + std::to_string(parameter_count) +
                       ")");
    }
  };
  for (std::size_t l = 0; l < layers; ++l) {
    if (weight_index[l].rows() != layer_sizes[l + 1] || weight_index[l].cols() != layer_sizes[l] ||
        bias_index[l].size() != layer_sizes[l + 1]) {
      throw InputError("LibTorch layout: index table of layer " + std::to_string(l) +
                       " has the wrong shape");
    }
    for (Eigen::Index i = 0; i < weight_index[l].size(); ++i) mark(weight_index[l].data()[i]);
    for (Eigen::Index i = 0; i < bias_index[l].size(); ++i) mark(bias_index[l](i));
  }
  if (std::count(seen.begin(), seen.end(), 1) != parameter_count) {
    throw InputError("LibTorch layout: the index tables do not cover all " +
                     std::to_string(parameter_count) + " parameters");
  }
}

Eigen::MatrixXd TorchForward(const FlatLayout& layout, const Eigen::VectorXd& w,
                             const Eigen::MatrixXd& x_norm) {
  Prepare();
  CheckData(layout, x_norm, nullptr);
  ::torch::NoGradGuard no_grad;
  WhirlNet net(layout, w);
  return ToEigenMatrix(net->ForwardNormalized(SamplesToTensor(x_norm)).t());
}

Eigen::MatrixXd TorchJacobian(const FlatLayout& layout, const Eigen::VectorXd& w,
                              const Eigen::MatrixXd& x_norm) {
  Prepare();
  CheckData(layout, x_norm, nullptr);
  WhirlNet net(layout, w);
  const std::vector<Tensor> params = net->LayerParameters();
  const Tensor y = net->ForwardNormalized(SamplesToTensor(x_norm));  // [Q, outputs]
  const int q_count = static_cast<int>(x_norm.cols()), outputs = layout.layer_sizes.back();
  Eigen::MatrixXd jacobian(static_cast<Eigen::Index>(q_count) * outputs, layout.parameter_count);
  for (int q = 0; q < q_count; ++q) {
    for (int k = 0; k < outputs; ++k) {
      // de/dw = -dy/dw: one reverse pass per error entry.
      const Tensor e = -y.index({q, k});
      const std::vector<Tensor> grads =
          ::torch::autograd::grad({e}, params, {}, /*retain_graph=*/true, /*create_graph=*/false,
                                  /*allow_unused=*/true);
      std::vector<Tensor> filled;
      for (std::size_t i = 0; i < grads.size(); ++i) {
        filled.push_back(grads[i].defined() ? grads[i] : ::torch::zeros_like(params[i]));
      }
      jacobian.row(layout.ErrorIndex(k, q, q_count)) = net->Flatten(filled).transpose();
    }
  }
  return jacobian;
}

TorchObjective TorchEvaluate(const FlatLayout& layout, const Eigen::VectorXd& w,
                             const Eigen::MatrixXd& x_norm, const Eigen::MatrixXd& t_norm,
                             double alpha, double beta) {
  Prepare();
  CheckData(layout, x_norm, &t_norm);
  WhirlNet net(layout, w);
  Tensor sse, ssx;
  const Tensor f =
      Objective(net, SamplesToTensor(x_norm), SamplesToTensor(t_norm), alpha, beta, &sse, &ssx);
  const std::vector<Tensor> params = net->LayerParameters();
  const std::vector<Tensor> grads = ::torch::autograd::grad({f}, params);
  TorchObjective out;
  out.objective = f.item<double>();
  out.sum_squared_errors = sse.item<double>();
  out.sum_squared_weights = ssx.item<double>();
  out.gradient = net->Flatten(grads);
  return out;
}

std::string ToString(LbfgsTermination t) {
  switch (t) {
    case LbfgsTermination::kGradientTolerance:
      return "gradient_tolerance";
    case LbfgsTermination::kNoProgress:
      return "no_progress";
    case LbfgsTermination::kMaxSteps:
      return "max_steps";
    case LbfgsTermination::kNonFinite:
      return "non_finite";
  }
  return "unknown";
}

std::string LbfgsSummary::BriefReport() const {
  return "LBFGS (LibTorch, strong Wolfe" +
         std::string(preconditioned ? ", Gauss-Newton preconditioner" : "") + "): F " +
         MessageNumber(initial_objective) + " -> " + MessageNumber(final_objective) + " in " +
         std::to_string(iterations) + " iterations (" + std::to_string(steps) + " steps, " +
         std::to_string(function_evaluations) + " evaluations), " + ToString(termination) + " (" +
         message + ")";
}

namespace {

void CheckLbfgsOptions(const LbfgsOptions& options) {
  if (options.max_steps < 1 || options.iterations_per_step < 1 || options.history_size < 1 ||
      !(options.gradient_tolerance > 0) || !(options.change_tolerance >= 0)) {
    throw InputError(
        "LBFGS options: max_steps, iterations_per_step, history_size must be >= 1, "
        "gradient_tolerance > 0 and change_tolerance >= 0");
  }
}

// LibTorch's LBFGS for one step of TorchMinimize: unit learning rate, strong Wolfe line search.
::torch::optim::LBFGSOptions TorchLbfgsOptions(const LbfgsOptions& options) {
  return ::torch::optim::LBFGSOptions(1.0)
      .max_iter(options.iterations_per_step)
      .history_size(options.history_size)
      .tolerance_grad(options.gradient_tolerance)
      .tolerance_change(options.change_tolerance)
      .line_search_fn("strong_wolfe");
}

// Iterations an LBFGS optimizer has made so far (its state's n_iter).
int IterationsOf(const ::torch::optim::LBFGS& optimizer) {
  int64_t n = 0;
  for (const auto& kv : optimizer.state()) {
    n = static_cast<const ::torch::optim::LBFGSParamState&>(*kv.second).n_iter();
  }
  return static_cast<int>(n);
}

// F = beta ssE + alpha ssX of the network parameters `params` on fixed data, counting every
// evaluation (with its gradient) for LbfgsSummary::function_evaluations.
struct CountedObjective {
  const std::vector<Tensor>& params;
  const Tensor& x;
  const Tensor& t;
  double alpha, beta;
  int evaluations = 0;

  // F at the parameters `w` (shaped like params), with its autograd graph.
  Tensor At(const std::vector<Tensor>& w) const {
    return ObjectiveWith(w, x, t, alpha, beta, nullptr, nullptr);
  }
  // F and the inf-norm of dF/dw at the current parameters.
  void Evaluate(double* f, double* g_inf) {
    const Tensor value = At(params);
    const std::vector<Tensor> grads = ::torch::autograd::grad({value}, params);
    double worst = 0;
    for (const Tensor& g : grads) worst = std::max(worst, g.abs().max().item<double>());
    ++evaluations;
    *f = value.item<double>();
    *g_inf = worst;
  }
};

// One preconditioned step: LBFGS on z with w = w_c + M z (the same F, Hessian ~ 2 I near w_c),
// from z = 0; the parameters are then set to w_c + M z. Returns the LBFGS iterations.
int PreconditionedStep(const Tensor& m, const LbfgsOptions& options, CountedObjective& objective) {
  const std::vector<Tensor>& params = objective.params;
  const Tensor w_c = CatParameters(params);
  Tensor z = ::torch::zeros({w_c.size(0)}, kF64).requires_grad_(true);
  ::torch::optim::LBFGS optimizer({z}, TorchLbfgsOptions(options));
  auto closure = [&]() -> Tensor {
    optimizer.zero_grad();
    Tensor value = objective.At(SplitParameters(w_c + m.mv(z), params));
    value.backward();
    ++objective.evaluations;
    return value;
  };
  optimizer.step(closure);
  const int iterations = IterationsOf(optimizer);
  ::torch::NoGradGuard no_grad;
  const std::vector<Tensor> w_new = SplitParameters(w_c + m.mv(z.detach()), params);
  for (std::size_t k = 0; k < params.size(); ++k) params[k].copy_(w_new[k]);
  return iterations;
}

// The termination of a run that used all its steps without another stop: the gradient test at
// the final point, or max_steps.
void SetEndOfSteps(double g_inf, const LbfgsOptions& options, LbfgsSummary* summary) {
  if (g_inf <= options.gradient_tolerance) {
    summary->termination = LbfgsTermination::kGradientTolerance;
    summary->message = "||dF/dw||_inf " + MessageNumber(g_inf) +
                       " <= " + MessageNumber(options.gradient_tolerance);
  } else {
    summary->message = std::to_string(options.max_steps) + " steps, ||dF/dw||_inf " +
                       MessageNumber(g_inf) + " > " + MessageNumber(options.gradient_tolerance);
  }
}

}  // namespace

LbfgsSummary TorchMinimize(const FlatLayout& layout, const Eigen::VectorXd& w0,
                           const Eigen::MatrixXd& x_norm, const Eigen::MatrixXd& t_norm,
                           double alpha, double beta, const LbfgsOptions& options) {
  Prepare();
  CheckData(layout, x_norm, &t_norm);
  CheckLbfgsOptions(options);
  WhirlNet net(layout, w0);
  const Tensor x = SamplesToTensor(x_norm), t = SamplesToTensor(t_norm);
  const std::vector<Tensor> params = net->LayerParameters();
  CountedObjective objective{params, x, t, alpha, beta};
  // Plain LBFGS keeps one optimizer (and its history) over all steps.
  ::torch::optim::LBFGS plain(params, TorchLbfgsOptions(options));
  auto plain_closure = [&]() -> Tensor {
    plain.zero_grad();
    Tensor f = objective.At(params);
    f.backward();
    ++objective.evaluations;
    return f;
  };

  LbfgsSummary summary;
  double f = 0, g_inf = 0;
  objective.Evaluate(&f, &g_inf);
  summary.initial_objective = f;
  summary.termination = LbfgsTermination::kMaxSteps;
  int preconditioned_iterations = 0;
  for (int step = 0; step < options.max_steps; ++step) {
    if (!std::isfinite(f) || !std::isfinite(g_inf)) {
      summary.termination = LbfgsTermination::kNonFinite;
      summary.message = "F = " + MessageNumber(f) + ", ||g||_inf = " + MessageNumber(g_inf);
      break;
    }
    if (g_inf <= options.gradient_tolerance) break;
    const double f_before = f;
    Tensor m;
    if (options.gauss_newton_preconditioner) m = GaussNewtonPreconditioner(params, x, alpha, beta);
    if (m.defined())
      preconditioned_iterations += PreconditionedStep(m, options, objective);
    else
      plain.step(plain_closure);
    ++summary.steps;
    objective.Evaluate(&f, &g_inf);
    if (std::isfinite(f) && f >= f_before && g_inf > options.gradient_tolerance) {
      summary.termination = LbfgsTermination::kNoProgress;
      summary.message = "a step left F at " + MessageNumber(f) + " (was " +
                        MessageNumber(f_before) + "), ||dF/dw||_inf " + MessageNumber(g_inf) +
                        " > " + MessageNumber(options.gradient_tolerance);
      break;
    }
  }
  if (summary.termination == LbfgsTermination::kMaxSteps) SetEndOfSteps(g_inf, options, &summary);
  summary.iterations = preconditioned_iterations + IterationsOf(plain);
  summary.preconditioned = options.gauss_newton_preconditioner;
  summary.final_objective = f;
  summary.final_gradient_inf = g_inf;
  summary.function_evaluations = objective.evaluations;
  std::vector<Tensor> detached;
  for (const Tensor& p : params) detached.push_back(p.detach());
  summary.w = net->Flatten(detached);
  return summary;
}

Eigen::MatrixXd TorchPredictRaw(const ModelSpec& spec, const Eigen::MatrixXd& x_raw) {
  Prepare();
  CheckData(spec.layout, x_raw, nullptr);
  ::torch::NoGradGuard no_grad;
  WhirlNet net = MakeNet(spec);
  return ToEigenMatrix(net->ForwardRaw(SamplesToTensor(x_raw)).t());
}

void SaveTorchScript(const std::filesystem::path& path, const ModelSpec& spec) {
  Prepare();
  ::torch::NoGradGuard no_grad;
  WhirlNet net = MakeNet(spec);
  const int inputs = spec.layout.layer_sizes.front();
  const int layers = static_cast<int>(spec.layout.layer_sizes.size()) - 1;
  if (static_cast<int>(spec.input_names.size()) != inputs ||
      static_cast<int>(spec.target_names.size()) != spec.layout.layer_sizes.back()) {
    throw InputError("TorchScript export: names do not match the layer sizes");
  }
  ::torch::jit::Module module("WhirlElongationModel");
  // Weights as parameters (trainable in PyTorch), scaling as buffers; all float64.
  for (const auto& p : net->named_parameters()) {
    module.register_parameter(p.key(), p.value().detach().clone(), /*is_buffer=*/false);
  }
  for (const auto& b : net->named_buffers()) {
    module.register_buffer(b.key(), b.value().detach().clone());
  }
  c10::List<std::string> in_names, out_names;
  for (const auto& n : spec.input_names) in_names.push_back(n);
  for (const auto& n : spec.target_names) out_names.push_back(n);
  module.register_attribute("input_names_list", c10::ListType::ofStrings(), in_names);
  module.register_attribute("target_names_list", c10::ListType::ofStrings(), out_names);
  module.register_attribute("description_text", c10::StringType::get(), spec.description);
  module.define(ScriptSource(layers, inputs));
  module.eval();
  std::ostringstream bytes;
  module.save(bytes);
  WriteFileAtomic(path, bytes.str());
}

namespace {
::torch::jit::Module LoadScript(const std::filesystem::path& path) {
  try {
    return ::torch::jit::load(path.string());
  } catch (const c10::Error& e) {
    throw InputError("cannot load TorchScript file '" + path.string() +
                     "': " + e.what_without_backtrace());
  } catch (const std::exception& e) {
    throw InputError("cannot load TorchScript file '" + path.string() + "': " + e.what());
  }
}

// Runs `forward` (a call of a loaded script) without autograd and turns LibTorch's errors into
// InputError naming the file.
template <typename Forward>
auto RunScript(const std::filesystem::path& path, Forward forward) -> decltype(forward()) {
  ::torch::NoGradGuard no_grad;
  try {
    return forward();
  } catch (const InputError&) {
    throw;
  } catch (const c10::Error& e) {
    throw InputError("TorchScript file '" + path.string() +
                     "' failed to run: " + e.what_without_backtrace());
  } catch (const std::exception& e) {  // torch::jit::JITException (a failed assert in forward)
    throw InputError("TorchScript file '" + path.string() + "' failed to run: " + e.what());
  }
}
}  // namespace

Eigen::MatrixXd RunTorchScript(const std::filesystem::path& path, const Eigen::MatrixXd& x_raw) {
  Prepare();
  ::torch::jit::Module module = LoadScript(path);
  return RunScript(path, [&] {
    const Tensor y = module.forward({SamplesToTensor(x_raw)}).toTensor();
    return ToEigenMatrix(y.t());
  });
}

Eigen::VectorXd RunTorchScriptOne(const std::filesystem::path& path, const Eigen::VectorXd& x_raw) {
  Prepare();
  ::torch::jit::Module module = LoadScript(path);
  return RunScript(path, [&]() -> Eigen::VectorXd {
    const Tensor y = module.forward({ToTensor(x_raw)}).toTensor();
    if (y.dim() != 1)
      throw InputError("TorchScript file '" + path.string() + "': a 1-D input gave a " +
                       std::to_string(y.dim()) + "-D result");
    return ToEigenMatrix(y.reshape({-1, 1})).col(0);
  });
}

std::vector<std::string> TorchScriptNames(const std::filesystem::path& path, bool inputs) {
  Prepare();
  ::torch::jit::Module module = LoadScript(path);
  const c10::IValue v = module.get_method(inputs ? "input_names" : "target_names")({});
  std::vector<std::string> out;
  for (const c10::IValue& s : v.toListRef()) out.push_back(s.toStringRef());
  return out;
}

std::string TorchVersion() { return "LibTorch " TORCH_VERSION; }

}  // namespace whirl::torch
