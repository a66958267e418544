// Torch-free: the Eigen side of the cross-check and the comparisons. LibTorch is reached only
// through libtorch_network.h.
#include "torch/crosscheck.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"

namespace whirl::torch {
namespace {

double MaxAbs(const Eigen::MatrixXd& m) { return m.size() == 0 ? 0.0 : m.cwiseAbs().maxCoeff(); }

void RequireFinite(const Eigen::MatrixXd& m, const std::string& what) {
  if (!m.allFinite()) throw InputError(what + ": contains a non-finite value (NaN or inf)");
}

/// F, J'e and ssE of nn's network at w (J = nn::ErrorJacobian).
struct EigenObjective {
  double objective = 0, sse = 0, ssx = 0;
  Eigen::VectorXd je;                ///< J'e
  Eigen::MatrixXd jacobian;          ///< J_e_w
  Eigen::VectorXd e;                 ///< errors, sample-major
  Eigen::VectorXd t_abs_plus_y_abs;  ///< |t| + |y|, sample-major
};

EigenObjective EvaluateEigen(nn::Network net, const Eigen::VectorXd& w, const Eigen::MatrixXd& x,
                             const Eigen::MatrixXd& t, double alpha, double beta) {
  net.SetParameters(w);
  nn::ForwardCache cache;
  net.Forward(x, &cache);
  EigenObjective out;
  const Eigen::MatrixXd e = t - cache.output();
  out.e = Eigen::Map<const Eigen::VectorXd>(e.data(), e.size());  // column-major = sample-major
  const Eigen::MatrixXd ty = t.cwiseAbs() + cache.output().cwiseAbs();
  out.t_abs_plus_y_abs = Eigen::Map<const Eigen::VectorXd>(ty.data(), ty.size());
  nn::ErrorJacobian(net, cache, &out.jacobian);
  out.sse = out.e.squaredNorm();
  out.ssx = w.squaredNorm();
  out.objective = beta * out.sse + alpha * out.ssx;
  out.je = out.jacobian.transpose() * out.e;
  return out;
}

double ObjectiveOnly(nn::Network net, const Eigen::VectorXd& w, const Eigen::MatrixXd& x,
                     const Eigen::MatrixXd& t, double alpha, double beta) {
  net.SetParameters(w);
  return beta * (t - net.Forward(x)).squaredNorm() + alpha * w.squaredNorm();
}

void CheckData(const nn::Network& net, const Eigen::MatrixXd& x, const Eigen::MatrixXd& t) {
  if (x.rows() != net.InputCount() || t.rows() != net.OutputCount() || x.cols() != t.cols() ||
      x.cols() < 1) {
    throw InputError("cross-check data: inputs " + std::to_string(x.rows()) + "x" +
                     std::to_string(x.cols()) + " and targets " + std::to_string(t.rows()) + "x" +
                     std::to_string(t.cols()) + " do not fit a network with " +
                     std::to_string(net.InputCount()) + " inputs and " +
                     std::to_string(net.OutputCount()) + " outputs (at least one sample)");
  }
  RequireFinite(x, "cross-check inputs");
  RequireFinite(t, "cross-check targets");
}

/// Largest relative difference with a floor on the denominator.
double MaxRelative(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b, double floor) {
  double worst = 0;
  for (Eigen::Index i = 0; i < a.size(); ++i) {
    const double d = std::abs(a.data()[i] - b.data()[i]) / std::max(std::abs(b.data()[i]), floor);
    if (!(d <= worst)) worst = d;  // keeps NaN
  }
  return worst;
}

/// nn::PredictBatch means as a matrix (outputs x Q), original units.
Eigen::MatrixXd PredictMeans(const nn::Model& model, const Eigen::MatrixXd& x_raw) {
  std::vector<ProcessInputs> inputs;
  for (Eigen::Index q = 0; q < x_raw.cols(); ++q) {
    std::array<double, ProcessInputs::kCount> a{};
    for (int i = 0; i < ProcessInputs::kCount; ++i) a[static_cast<std::size_t>(i)] = x_raw(i, q);
    inputs.push_back(ProcessInputs::FromArray(a));
  }
  const std::vector<nn::Prediction> predictions = nn::PredictBatch(model, inputs);
  std::vector<Features> means;
  for (const auto& p : predictions) means.push_back(p.mean);
  return nn::TargetMatrix(means);
}

}  // namespace

FlatLayout MakeLayout(const nn::Network& net) {
  net.Validate("cross-check network");
  FlatLayout layout;
  layout.layer_sizes = net.layer_sizes;
  layout.parameter_count = net.ParameterCount();
  layout.errors_sample_major = true;  // nn/network.h: flat error index q * S + k
  for (int l = 0; l < net.LayerCount(); ++l) {
    const int rows = net.layer_sizes[l + 1], cols = net.layer_sizes[l];
    Eigen::MatrixXi wi(rows, cols);
    Eigen::VectorXi bi(rows);
    for (int r = 0; r < rows; ++r) {
      bi(r) = net.BiasIndex(l, r);
      for (int c = 0; c < cols; ++c) wi(r, c) = net.WeightIndex(l, r, c);
    }
    layout.weight_index.push_back(wi);
    layout.bias_index.push_back(bi);
  }
  layout.Validate();
  return layout;
}

ModelSpec MakeModelSpec(const nn::Model& model, const std::string& description) {
  ModelSpec spec;
  spec.layout = MakeLayout(model.network);
  spec.w = model.network.GetParameters();
  spec.input_min = model.input_scaling.xmin;
  spec.input_max = model.input_scaling.xmax;
  spec.target_min = model.target_scaling.xmin;
  spec.target_max = model.target_scaling.xmax;
  for (const auto& v : model.inputs) spec.input_names.push_back(v.name);
  for (const auto& v : model.outputs) spec.target_names.push_back(v.name);
  spec.description = description;
  return spec;
}

std::string ToString(GaussNewtonTermination t) {
  switch (t) {
    case GaussNewtonTermination::kGradientTolerance:
      return "gradient_tolerance";
    case GaussNewtonTermination::kMaxMu:
      return "max_mu";
    case GaussNewtonTermination::kMaxIterations:
      return "max_iterations";
  }
  return "unknown";
}

std::string GaussNewtonSummary::BriefReport() const {
  return "Gauss-Newton (Eigen, nn Jacobian): F " + FormatSignificant(initial_objective, 10) +
         " -> " + FormatSignificant(final_objective, 10) + " in " + std::to_string(iterations) +
         " iterations, " + ToString(termination) + " (" + message + ")";
}

GaussNewtonSummary MinimizeFixedHyperparameters(const nn::Network& start, const Eigen::MatrixXd& x,
                                                const Eigen::MatrixXd& t, double alpha, double beta,
                                                const GaussNewtonOptions& options) {
  start.Validate("Gauss-Newton start network");
  CheckData(start, x, t);
  if (!(alpha >= 0) || !(beta > 0) || !std::isfinite(alpha) || !std::isfinite(beta)) {
    throw InputError("Gauss-Newton: alpha = " + FormatSignificant(alpha, 3) + ", beta = " +
                     FormatSignificant(beta, 3) + " (need alpha >= 0, beta > 0, finite)");
  }
  if (options.max_iterations < 1 || !(options.gradient_tolerance > 0) || !(options.mu > 0) ||
      !(options.mu_dec > 0 && options.mu_dec < 1) || !(options.mu_inc > 1) ||
      !(options.mu_max > options.mu)) {
    throw InputError(
        "Gauss-Newton options: need max_iterations >= 1, gradient_tolerance > 0, "
        "mu > 0, 0 < mu_dec < 1, mu_inc > 1, mu_max > mu");
  }
  const int n_params = start.ParameterCount();
  Eigen::VectorXd w = start.GetParameters();
  EigenObjective cur = EvaluateEigen(start, w, x, t, alpha, beta);
  GaussNewtonSummary summary;
  summary.initial_objective = cur.objective;
  double mu = options.mu;
  const Eigen::MatrixXd identity = Eigen::MatrixXd::Identity(n_params, n_params);
  double g_inf = 0;
  for (;;) {
    g_inf = (2.0 * (beta * cur.je + alpha * w)).cwiseAbs().maxCoeff();
    if (g_inf <= options.gradient_tolerance) {
      summary.termination = GaussNewtonTermination::kGradientTolerance;
      summary.message = "||dF/dw||_inf " + FormatSignificant(g_inf, 3) +
                        " <= " + FormatSignificant(options.gradient_tolerance, 3);
      break;
    }
    if (summary.iterations >= options.max_iterations) {
      summary.termination = GaussNewtonTermination::kMaxIterations;
      summary.message = std::to_string(options.max_iterations) + " iterations, ||dF/dw||_inf " +
                        FormatSignificant(g_inf, 3) + " > " +
                        FormatSignificant(options.gradient_tolerance, 3);
      break;
    }
    if (mu > options.mu_max) {
      summary.termination = GaussNewtonTermination::kMaxMu;
      summary.message = "mu " + FormatSignificant(mu, 3) + " > " +
                        FormatSignificant(options.mu_max, 3) +
                        ": no step lowers F = " + FormatSignificant(cur.objective, 17) +
                        ", ||dF/dw||_inf " + FormatSignificant(g_inf, 3);
      break;
    }
    ++summary.iterations;
    const Eigen::MatrixXd jj = cur.jacobian.transpose() * cur.jacobian;
    const Eigen::VectorXd rhs = beta * cur.je + alpha * w;
    bool accepted = false;
    while (mu <= options.mu_max) {
      const Eigen::MatrixXd h = beta * jj + (mu + alpha) * identity;
      const Eigen::VectorXd dw = -h.ldlt().solve(rhs);
      const Eigen::VectorXd w_new = w + dw;
      const double f_new = dw.allFinite() ? ObjectiveOnly(start, w_new, x, t, alpha, beta)
                                          : std::numeric_limits<double>::quiet_NaN();
      if (f_new < cur.objective) {
        w = w_new;
        mu = std::max(mu * options.mu_dec, 1e-20);
        accepted = true;
        break;
      }
      mu *= options.mu_inc;
    }
    if (accepted) cur = EvaluateEigen(start, w, x, t, alpha, beta);
  }
  summary.final_objective = cur.objective;
  summary.final_gradient_inf = g_inf;
  summary.w = w;
  return summary;
}

void CrosscheckOptions::Validate() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v)) {
      throw InputError(std::string("cross-check option ") + name + " = " + FormatSignificant(v, 3) +
                       ": must be a positive finite number");
    }
  };
  positive(forward_tolerance, "forward_tolerance");
  positive(jacobian_tolerance, "jacobian_tolerance");
  positive(objective_tolerance, "objective_tolerance");
  positive(gradient_tolerance, "gradient_tolerance");
  positive(training_objective_tolerance, "training_objective_tolerance");
  positive(training_prediction_tolerance, "training_prediction_tolerance");
  if (!std::isfinite(alpha) || !std::isfinite(beta)) {
    throw InputError("cross-check option alpha/beta: must be finite (<= 0 = the model's values)");
  }
  if (!(start_perturbation >= 0 && start_perturbation <= 1)) {
    throw InputError(
        "cross-check option start_perturbation = " + FormatSignificant(start_perturbation, 3) +
        ": must be in [0, 1] (relative change of each starting weight)");
  }
}

void to_json(nlohmann::json& j, const CrosscheckFigure& f) {
  j = nlohmann::json{{"name", f.name},
                     {"value", std::isfinite(f.value) ? nlohmann::json(f.value) : nlohmann::json()},
                     {"tolerance", f.tolerance},
                     {"passed", f.Passed()},
                     {"definition", f.definition}};
}

bool CrosscheckReport::Passed() const {
  return std::all_of(figures.begin(), figures.end(),
                     [](const CrosscheckFigure& f) { return f.Passed(); });
}

std::string CrosscheckReport::Table() const {
  std::ostringstream s;
  s << "LibTorch cross-check (" << torch_version << ", float64, 1 thread): " << sample_count
    << " samples, N = " << parameter_count << " weights, alpha = " << MessageNumber(alpha)
    << ", beta = " << MessageNumber(beta) << "\n";
  s << std::left << std::setw(24) << "figure" << std::setw(12) << "value" << std::setw(12)
    << "tolerance" << std::setw(6) << ""
    << "definition\n";
  for (const auto& f : figures) {
    s << std::left << std::setw(24) << f.name << std::setw(12) << FormatSignificant(f.value, 3)
      << std::setw(12) << FormatSignificant(f.tolerance, 3) << std::setw(6)
      << (f.Passed() ? "ok" : "FAIL") << f.definition << "\n";
  }
  s << eigen_training.BriefReport() << "\n" << torch_training.BriefReport() << "\n";
  return s.str();
}

std::string CrosscheckReport::BriefReport() const {
  int passed = 0;
  const CrosscheckFigure* worst = nullptr;
  double worst_ratio = -1;
  for (const auto& f : figures) {
    if (f.Passed()) ++passed;
    const double ratio = f.value / f.tolerance;
    if (!(ratio <= worst_ratio)) {
      worst_ratio = ratio;
      worst = &f;
    }
  }
  std::string out = "crosscheck: " + std::to_string(passed) + "/" + std::to_string(figures.size()) +
                    " figures within tolerance";
  if (worst != nullptr) {
    out += " (closest to its limit: " + worst->name + " " + FormatSignificant(worst->value, 3) +
           (worst->Passed() ? " <= " : " > ") + FormatSignificant(worst->tolerance, 3) + ")";
  }
  return out;
}

void to_json(nlohmann::json& j, const CrosscheckReport& r) {
  const auto finite = [](double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
  };
  j = nlohmann::json{
      {"schema", "whirl.crosscheck/1"},
      {"torch_version", r.torch_version},
      {"passed", r.Passed()},
      {"sample_count", r.sample_count},
      {"parameter_count", r.parameter_count},
      {"alpha", r.alpha},
      {"beta", r.beta},
      {"figures", r.figures},
      {"eigen_training",
       {{"method", "damped Gauss-Newton (trainbr LM loop, alpha/beta fixed), nn::ErrorJacobian"},
        {"initial_objective", finite(r.eigen_training.initial_objective)},
        {"final_objective", finite(r.eigen_training.final_objective)},
        {"final_gradient_inf", finite(r.eigen_training.final_gradient_inf)},
        {"iterations", r.eigen_training.iterations},
        {"termination", ToString(r.eigen_training.termination)},
        {"message", r.eigen_training.message}}},
      {"torch_training",
       {{"method", r.torch_training.preconditioned
                       ? "torch::optim::LBFGS, strong Wolfe line search, autograd gradient, "
                         "Gauss-Newton preconditioner (autograd Jacobian) per step"
                       : "torch::optim::LBFGS, strong Wolfe line search, autograd gradient"},
        {"initial_objective", finite(r.torch_training.initial_objective)},
        {"final_objective", finite(r.torch_training.final_objective)},
        {"final_gradient_inf", finite(r.torch_training.final_gradient_inf)},
        {"iterations", r.torch_training.iterations},
        {"steps", r.torch_training.steps},
        {"function_evaluations", r.torch_training.function_evaluations},
        {"termination", ToString(r.torch_training.termination)},
        {"message", r.torch_training.message}}}};
}

namespace {

// The common start of both trainings: the model's weights, each times 1 + p u, u ~ U(-1, 1)
// seeded (CrosscheckOptions::start_perturbation, seed).
Eigen::VectorXd PerturbedStart(const Eigen::VectorXd& w_model, const CrosscheckOptions& options) {
  Eigen::VectorXd w0 = w_model;
  Rng rng(options.seed);
  for (Eigen::Index i = 0; i < w0.size(); ++i) {
    w0(i) *= 1.0 + options.start_perturbation * rng.Uniform(-1.0, 1.0);
  }
  return w0;
}

// The data of one cross-check in the model's normalized space, the layout and the two weight
// vectors compared (the model's and the perturbed start).
struct CrosscheckData {
  const nn::Model& model;
  const Eigen::MatrixXd& inputs_raw;
  FlatLayout layout;
  Eigen::MatrixXd x, t;  // normalized inputs and targets
  Eigen::VectorXd w_model, w0;
  double alpha = 0, beta = 0;
};

// Figures 1 and 2: forward outputs of the normalized network and of the whole model in original
// units (scaling included).
void AddForwardFigures(const CrosscheckData& d, const CrosscheckOptions& options,
                       CrosscheckReport* report) {
  const nn::Model& model = d.model;
  const nn::Network& net = model.network;
  const Eigen::MatrixXd& x = d.x;
  const Eigen::MatrixXd& inputs_raw = d.inputs_raw;
  // 1. Forward, normalized network outputs.
  const Eigen::MatrixXd y_eigen = net.Forward(x);
  const Eigen::MatrixXd y_torch = TorchForward(d.layout, d.w_model, x);
  report->figures.push_back({"forward", MaxRelative(y_torch, y_eigen, 1.0),
                             options.forward_tolerance,
                             "max |y_T - y_E| / max(|y_E|, 1), network outputs (normalized)"});

  // 2. Forward, whole model in original units (scaling included).
  const ModelSpec spec = MakeModelSpec(model);
  const Eigen::MatrixXd raw_torch = TorchPredictRaw(spec, inputs_raw);
  const Eigen::MatrixXd raw_eigen = PredictMeans(model, inputs_raw);
  report->figures.push_back(
      {"forward_original_units", MaxRelative(raw_torch, raw_eigen, 1e-300),
       options.forward_tolerance,
       "max |y_T - y_E| / |y_E|, model in original units: torch::nn::Module vs nn::Predict"});
}

// Figure 3: the Jacobian J_e_w at the model's weights and at the start.
CrosscheckFigure JacobianFigure(const CrosscheckData& d, const CrosscheckOptions& options) {
  const nn::Network& net = d.model.network;
  double jac = 0;
  for (const Eigen::VectorXd* w : {&d.w_model, &d.w0}) {
    const EigenObjective e = EvaluateEigen(net, *w, d.x, d.t, d.alpha, d.beta);
    const Eigen::MatrixXd j_torch = TorchJacobian(d.layout, *w, d.x);
    jac = std::max(jac, MaxAbs(j_torch - e.jacobian) / std::max(1.0, MaxAbs(e.jacobian)));
    if (!j_torch.allFinite()) jac = std::numeric_limits<double>::quiet_NaN();
  }
  return {"jacobian", jac, options.jacobian_tolerance,
          "max |J_T - J_E| / max(1, max |J_E|), J = de/dw, autograd vs "
          "nn::ErrorJacobian, at w_model and w0"};
}

// Figures 4 and 5: the objective and its gradient at the model's weights and at the start.
void AddObjectiveFigures(const CrosscheckData& d, const CrosscheckOptions& options,
                         CrosscheckReport* report) {
  const nn::Network& net = d.model.network;
  const double alpha = d.alpha, beta = d.beta;
  double obj = 0, grad = 0;
  for (const Eigen::VectorXd* w : {&d.w_model, &d.w0}) {
    const EigenObjective e = EvaluateEigen(net, *w, d.x, d.t, alpha, beta);
    const TorchObjective tt = TorchEvaluate(d.layout, *w, d.x, d.t, alpha, beta);
    obj = std::max(obj, std::abs(tt.objective - e.objective) / std::abs(e.objective));
    const Eigen::VectorXd g_eigen = 2.0 * (beta * e.je + alpha * *w);
    // e = t - y cancels when the fit is close: two correct implementations differ by ~eps |y|
    // in each e, so the scale counts the magnitudes entering e, |t| + |y| (>= |e|).
    const Eigen::VectorXd ty = e.t_abs_plus_y_abs;
    const Eigen::VectorXd scale =
        2.0 * (beta * e.jacobian.cwiseAbs().transpose() * ty + alpha * w->cwiseAbs());
    grad = std::max(grad, (tt.gradient - g_eigen).cwiseAbs().maxCoeff() / scale.maxCoeff());
    if (!std::isfinite(tt.objective) || !tt.gradient.allFinite()) {
      obj = grad = std::numeric_limits<double>::quiet_NaN();
    }
  }
  report->figures.push_back({"objective", obj, options.objective_tolerance,
                             "|F_T - F_E| / |F_E|, F = beta ssE + alpha ssX, at w_model and w0"});
  report->figures.push_back(
      {"gradient", grad, options.gradient_tolerance,
       "max |g_T - g_E| / max(2 beta |J|'(|t|+|y|) + 2 alpha |w|), g = dF/dw, "
       "autograd vs 2(beta J'e + alpha w)"});
}

// Figures 6 and 7: both trainings with alpha, beta fixed from the same start, their minima and
// predictions.
void AddTrainingFigures(const CrosscheckData& d, const CrosscheckOptions& options,
                        CrosscheckReport* report) {
  const nn::Network& net = d.model.network;
  const Eigen::MatrixXd& x = d.x;
  nn::Network start = net;
  start.SetParameters(d.w0);
  report->eigen_training =
      MinimizeFixedHyperparameters(start, x, d.t, d.alpha, d.beta, options.eigen_training);
  report->torch_training =
      TorchMinimize(d.layout, d.w0, x, d.t, d.alpha, d.beta, options.torch_training);
  const double f_e = report->eigen_training.final_objective;
  const double f_t = report->torch_training.final_objective;
  report->figures.push_back({"training_objective", std::abs(f_t - f_e) / std::abs(f_e),
                             options.training_objective_tolerance,
                             "|F_LBFGS - F_GN| / |F_GN| at the two minima (alpha, beta fixed)"});
  nn::Network trained_eigen = net, trained_torch = net;
  trained_eigen.SetParameters(report->eigen_training.w);
  trained_torch.SetParameters(report->torch_training.w);
  const double pred = MaxAbs(trained_torch.Forward(x) - trained_eigen.Forward(x));
  report->figures.push_back({"training_prediction", std::isfinite(pred) ? pred : NAN,
                             options.training_prediction_tolerance,
                             "max |y_LBFGS - y_GN| on the data, normalized target units"});
}

}  // namespace

CrosscheckReport RunCrosscheck(const nn::Model& model, const Eigen::MatrixXd& inputs_raw,
                               const Eigen::MatrixXd& targets_raw,
                               const CrosscheckOptions& options) {
  options.Validate();
  const nn::Network& net = model.network;
  const FlatLayout layout = MakeLayout(net);
  CheckData(net, inputs_raw, targets_raw);
  CrosscheckData d{model,
                   inputs_raw,
                   layout,
                   model.input_scaling.Apply(inputs_raw),
                   model.target_scaling.Apply(targets_raw),
                   net.GetParameters(),
                   /*w0=*/{},
                   /*alpha=*/0,
                   /*beta=*/0};

  CrosscheckReport report;
  report.torch_version = TorchVersion();
  report.sample_count = static_cast<int>(d.x.cols());
  report.parameter_count = net.ParameterCount();
  report.alpha = options.alpha > 0 ? options.alpha : model.training_summary.alpha;
  report.beta = options.beta > 0 ? options.beta : model.training_summary.beta;
  if (!(report.alpha >= 0) || !(report.beta > 0)) {
    throw InputError("cross-check: the model has no usable trainbr alpha = " +
                     FormatSignificant(report.alpha, 3) + ", beta = " +
                     FormatSignificant(report.beta, 3) + " (need alpha >= 0, beta > 0); pass them");
  }
  d.alpha = report.alpha;
  d.beta = report.beta;
  d.w0 = PerturbedStart(d.w_model, options);
  AddForwardFigures(d, options, &report);
  report.figures.push_back(JacobianFigure(d, options));
  AddObjectiveFigures(d, options, &report);
  AddTrainingFigures(d, options, &report);
  return report;
}

CrosscheckReport RunCrosscheck(const nn::Model& model, const ProcessTable& table,
                               const CrosscheckOptions& options) {
  if (table.targets.size() != table.inputs.size() || table.inputs.empty()) {
    throw InputError(table.source + ": the cross-check needs a table with inputs and targets (" +
                     std::to_string(table.inputs.size()) + " input rows, " +
                     std::to_string(table.targets.size()) + " target rows)");
  }
  const Eigen::MatrixXd x = nn::InputMatrix(table.inputs);
  const Eigen::MatrixXd t = nn::TargetMatrix(table.targets);
  return RunCrosscheck(model, x, t, options);
}

ExportReport ExportTorchScript(const nn::Model& model, const std::filesystem::path& path,
                               const ExportOptions& options) {
  namespace fs = std::filesystem;
  if (!(options.tolerance > 0)) {
    throw InputError("TorchScript export: tolerance = " + FormatSignificant(options.tolerance, 3) +
                     ": must be positive");
  }
  model.Validate();
  const ModelSpec spec = MakeModelSpec(model, options.description);
  Eigen::MatrixXd x = options.check_inputs_raw;
  if (x.size() == 0) {
    // Corners of the training domain and its centre (2^R + 1 points).
    const Eigen::VectorXd lo = model.domain_min, hi = model.domain_max;
    const int r = static_cast<int>(lo.size());
    x.resize(r, (1 << r) + 1);
    for (int c = 0; c < (1 << r); ++c)
      for (int i = 0; i < r; ++i) x(i, c) = ((c >> i) & 1) ? hi(i) : lo(i);
    x.col(1 << r) = (lo + hi) / 2.0;
  }
  if (x.rows() != model.network.InputCount()) {
    throw InputError("TorchScript export check: inputs have " + std::to_string(x.rows()) +
                     " rows, the model takes " + std::to_string(model.network.InputCount()));
  }
  RequireFinite(x, "TorchScript export check inputs");
  // Verify a complete temporary file in the target directory, then rename it into place: a
  // failed check or an interrupted run leaves no file (and any previous file untouched).
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  // The writer's rule for the target (a symbolic link or directory there is refused), and a whirl
  // temporary (core/atomic_file.h): a killed run's leftover is recognised and removed.
  CheckOutputFile(path);
  RemoveStaleTemporaries(dir, path.filename().string());
  const fs::path tmp = dir / WhirlTemporaryName(path.filename().string(), ".whirl-tmp-");
  ExportReport report;
  report.path = path.string();
  report.check_points = static_cast<int>(x.cols());
  report.tolerance = options.tolerance;
  try {
    SaveTorchScript(tmp, spec);
    report.max_relative_difference =
        MaxRelative(RunTorchScript(tmp, x), PredictMeans(model, x), 1e-300);
    report.input_names = TorchScriptNames(tmp, true);
    report.target_names = TorchScriptNames(tmp, false);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
  std::error_code ec;
  if (!report.Passed()) {
    fs::remove(tmp, ec);
    return report;
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError("cannot write '" + path.string() + "': rename failed: " + ec.message());
  }
  report.written = true;
  return report;
}

void to_json(nlohmann::json& j, const ExportReport& r) {
  j = nlohmann::json{{"schema", "whirl.export/1"},
                     {"path", r.path},
                     {"written", r.written},
                     {"check_points", r.check_points},
                     {"max_relative_difference", std::isfinite(r.max_relative_difference)
                                                     ? nlohmann::json(r.max_relative_difference)
                                                     : nlohmann::json()},
                     {"tolerance", r.tolerance},
                     {"input_names", r.input_names},
                     {"target_names", r.target_names},
                     {"torch_version", TorchVersion()}};
}

}  // namespace whirl::torch
