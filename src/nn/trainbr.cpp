#include "nn/trainbr.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/numbers.h"
#include "core/parallel.h"
#include "nn/dense_kernels.h"

namespace whirl::nn {
namespace {

using detail::FactorShifted;
using detail::GramLower;
using detail::SolveFactored;
using detail::TraceOfInverse;

constexpr double kMuFloor = 1e-20;  // trainbr: mu = max(mu * mu_dec, 1e-20)

double SumSquares(const Eigen::MatrixXd& e) { return e.squaredNorm(); }

}  // namespace

std::string ToString(TrainTermination t) {
  switch (t) {
    case TrainTermination::kGoalMet:
      return "goal_met";
    case TrainTermination::kMaxEpochs:
      return "max_epochs";
    case TrainTermination::kMinGradient:
      return "min_gradient";
    case TrainTermination::kMaxMu:
      return "max_mu";
    case TrainTermination::kInterpolation:
      return "interpolation";
    case TrainTermination::kObjectiveStalled:
      return "objective_stalled";
  }
  return "unknown";
}

TrainTermination ParseTermination(const std::string& s) {
  for (auto t : {TrainTermination::kGoalMet, TrainTermination::kMaxEpochs,
                 TrainTermination::kMinGradient, TrainTermination::kMaxMu,
                 TrainTermination::kInterpolation, TrainTermination::kObjectiveStalled})
    if (ToString(t) == s) return t;
  throw InputError("termination '" + s +
                   "' is not one of goal_met, max_epochs, min_gradient, max_mu, interpolation, "
                   "objective_stalled");
}

std::string ToString(Regularization r) {
  return r == Regularization::kBayesian ? "bayesian" : "none";
}

Regularization ParseRegularization(const std::string& s) {
  if (s == "bayesian") return Regularization::kBayesian;
  if (s == "none") return Regularization::kNone;
  throw InputError("regularization '" + s + "' is not one of bayesian, none");
}

void TrainOptions::Validate() const {
  auto fail = [](const std::string& name, double v, const std::string& rule) {
    throw InputError("train option '" + name + "' = " + MessageNumber(v) + ": " + rule);
  };
  if (epochs < 0) fail("epochs", epochs, "must be >= 0");
  if (!(goal >= 0) || !std::isfinite(goal)) fail("goal", goal, "must be finite and >= 0");
  if (!(mu > 0) || !std::isfinite(mu)) fail("mu", mu, "must be finite and > 0");
  if (!(mu_dec > 0 && mu_dec < 1)) fail("mu_dec", mu_dec, "must be in (0, 1)");
  if (!(mu_inc > 1) || !std::isfinite(mu_inc)) fail("mu_inc", mu_inc, "must be finite and > 1");
  if (!(mu_max > mu)) fail("mu_max", mu_max, "must be > mu");
  if (!(min_grad >= 0) || !std::isfinite(min_grad))
    fail("min_grad", min_grad, "must be finite and >= 0");
  if (!(change >= 0) || !std::isfinite(change)) fail("change", change, "must be finite and >= 0");
  if (ard && regularization != Regularization::kBayesian)
    throw InputError("train option 'ard': needs Bayesian regularization");
}

namespace {

// The stopping tests of an epoch in the documented order (nn/trainbr.h, step 2): sets the
// termination and message of `sum` and returns true when one holds.
bool StopReached(const TrainOptions& options, int epoch, double sse, double gradient, double mu,
                 const std::vector<double>& after_step, const std::string& degenerate_message,
                 TrainSummary* sum) {
  if (!degenerate_message.empty()) {
    sum->termination = TrainTermination::kInterpolation;
    sum->message = degenerate_message;
  } else if (sse <= options.goal) {
    sum->termination = TrainTermination::kGoalMet;
    sum->message = "ssE = " + MessageNumber(sse) + " <= goal = " + MessageNumber(options.goal);
  } else if (epoch == options.epochs) {
    sum->termination = TrainTermination::kMaxEpochs;
    sum->message =
        "epoch = " + std::to_string(epoch) + " == epochs = " + std::to_string(options.epochs);
  } else if (gradient <= options.min_grad) {
    sum->termination = TrainTermination::kMinGradient;
    sum->message = "gradient 2||J'e|| = " + MessageNumber(gradient) +
                   " <= min_grad = " + MessageNumber(options.min_grad);
  } else if (mu >= options.mu_max) {
    sum->termination = TrainTermination::kMaxMu;
    sum->message = "mu = " + MessageNumber(mu) + " >= mu_max = " + MessageNumber(options.mu_max);
  } else if (options.change > 0 && ObjectiveSpread(after_step) < options.change) {
    sum->termination = TrainTermination::kObjectiveStalled;
    sum->message = "F after the step changed by at most " +
                   MessageNumber(ObjectiveSpread(after_step)) +
                   " < change = " + MessageNumber(options.change) + " over the last 4 epochs";
  } else {
    return false;
  }
  return true;
}

}  // namespace

double ObjectiveSpread(const std::vector<double>& after_step) {
  constexpr std::size_t kWindow = 4;  // brnn: 4 values, 3 consecutive differences
  if (after_step.size() < kWindow) return std::numeric_limits<double>::infinity();
  double spread = 0;
  for (std::size_t i = after_step.size() - kWindow + 1; i < after_step.size(); ++i)
    spread = std::max(spread, std::abs(after_step[i] - after_step[i - 1]));
  return spread;
}

std::string TrainSummary::BriefReport() const {
  // Four significant digits for a person to read; the model file keeps the exact values. No F:
  // trainbr starts and ends near F = n / 2 by its alpha/beta rule, so F tells nothing here.
  auto brief = [](double x) { return FormatSignificant(x, 4); };
  std::ostringstream s;
  s << (regularization == Regularization::kBayesian ? "trainbr" : "trainlm") << ": ssE "
    << brief(initial_sse) << " -> " << brief(sse) << " in " << epochs << " epochs, gamma "
    << brief(gamma) << " of " << parameter_count << ", " << ToString(termination) << " (" << message
    << ")";
  return s.str();
}

namespace {
nlohmann::json VecJson(const Eigen::VectorXd& v) {
  return std::vector<double>(v.data(), v.data() + v.size());
}
Eigen::VectorXd VecFromJson(const nlohmann::json& j, const char* key) {
  const std::vector<double> v = RequireNumbers(RequireKey(j, key, "training_summary"),
                                               std::string("training_summary: '") + key + "'");
  return Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size()));
}
// NaN (no regularization) is stored as null.
nlohmann::json MaybeNumber(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
}
double NumberOrNan(const nlohmann::json& j, const char* key) {
  const auto& v = RequireKey(j, key, "training_summary");
  if (v.is_null()) return std::numeric_limits<double>::quiet_NaN();
  return RequireFiniteValue(v, std::string("training_summary: '") + key + "'");
}
}  // namespace

void to_json(nlohmann::json& j, const TrainSummary& s) {
  j = nlohmann::json{{"epochs", s.epochs},
                     {"parameter_count", s.parameter_count},
                     {"error_count", s.error_count},
                     {"initial_cost", s.initial_cost},
                     {"final_cost", s.final_cost},
                     {"initial_sse_normalized", s.initial_sse},
                     {"sse_normalized", s.sse},
                     {"rms_error", VecJson(s.rms_error)},
                     {"rms_error_normalized", VecJson(s.rms_error_normalized)},
                     {"sum_squared_weights", s.sum_squared_weights},
                     {"gamma", s.gamma},
                     {"alpha", s.alpha},
                     {"beta", s.beta},
                     {"mu", s.mu},
                     {"gradient", s.gradient},
                     {"log_evidence", MaybeNumber(s.log_evidence)},
                     {"noise_variance_normalized", MaybeNumber(s.noise_variance)},
                     {"regularization", ToString(s.regularization)},
                     {"termination", ToString(s.termination)},
                     {"message", s.message}};
  if (s.ard_alpha.size() > 0) j["ard_alpha"] = VecJson(s.ard_alpha);  // optional key
}

void from_json(const nlohmann::json& j, TrainSummary& s) {
  if (!j.is_object()) throw InputError("training_summary: expected a JSON object");
  auto num = [&](const char* key) { return RequireNumber(j, key, "training_summary"); };
  // Counts checked before the cast (a float-to-int cast out of range is undefined behaviour).
  auto count = [&](const char* key) {
    return static_cast<int>(
        RequireInteger(j, key, 0, std::numeric_limits<int>::max(), "training_summary"));
  };
  s.epochs = count("epochs");
  s.parameter_count = count("parameter_count");
  s.error_count = count("error_count");
  s.initial_cost = num("initial_cost");
  s.final_cost = num("final_cost");
  s.initial_sse = num("initial_sse_normalized");
  s.sse = num("sse_normalized");
  s.rms_error = VecFromJson(j, "rms_error");
  s.rms_error_normalized = VecFromJson(j, "rms_error_normalized");
  s.sum_squared_weights = num("sum_squared_weights");
  s.gamma = num("gamma");
  s.alpha = num("alpha");
  s.beta = num("beta");
  s.mu = num("mu");
  s.gradient = num("gradient");
  s.log_evidence = NumberOrNan(j, "log_evidence");
  s.noise_variance = NumberOrNan(j, "noise_variance_normalized");
  s.regularization = ParseRegularization(j.at("regularization").get<std::string>());
  s.termination = ParseTermination(j.at("termination").get<std::string>());
  s.message = j.at("message").get<std::string>();
  s.ard_alpha.resize(0);
  if (j.contains("ard_alpha")) s.ard_alpha = VecFromJson(j, "ard_alpha");
}

void to_json(nlohmann::json& j, const RestartRecord& r) {
  j = nlohmann::json{{"seed", r.seed},          {"log_evidence", MaybeNumber(r.log_evidence)},
                     {"sse_normalized", r.sse}, {"gamma", r.gamma},
                     {"epochs", r.epochs},      {"termination", ToString(r.termination)}};
}

void from_json(const nlohmann::json& j, RestartRecord& r) {
  r.seed = j.at("seed").get<std::uint64_t>();
  r.log_evidence = NumberOrNan(j, "log_evidence");
  r.sse = j.at("sse_normalized").get<double>();
  r.gamma = j.at("gamma").get<double>();
  const double epochs = j.at("epochs").get<double>();  // checked before the cast (1e30 is UB)
  if (!(epochs >= 0 && epochs <= 1e9 && epochs == std::floor(epochs)))
    throw InputError("restart record: 'epochs' must be a whole number in [0, 1e9], got " +
                     j.at("epochs").dump());
  r.epochs = static_cast<int>(epochs);
  r.termination = ParseTermination(j.at("termination").get<std::string>());
}

double LogEvidence(double sse, double ssx, double alpha, double beta, double log_det_h,
                   int parameter_count, int error_count, const std::vector<int>& layer_sizes,
                   const std::vector<int>& active_units) {
  const double N = parameter_count;
  const double n = error_count;
  if (!active_units.empty() && active_units.size() + 2 != layer_sizes.size())
    throw InputError("log evidence: " + std::to_string(active_units.size()) +
                     " active-unit counts for " + std::to_string(layer_sizes.size() - 2) +
                     " hidden layers");
  double symmetry = 0;
  for (std::size_t l = 1; l + 1 < layer_sizes.size(); ++l) {
    const int S = layer_sizes[l];
    const int active = active_units.empty() ? S : active_units[l - 1];
    if (active < 0 || active > S)
      throw InputError("log evidence: " + std::to_string(active) +
                       " active neurons in a layer of " + std::to_string(S));
    // ln(2^active S! / (S - active)!): the distinct images of the weight vector
    symmetry += active * std::log(2.0) + std::lgamma(S + 1.0) - std::lgamma(S - active + 1.0);
  }
  const double F = beta * sse + alpha * ssx;
  return -F - 0.5 * log_det_h + 0.5 * N * std::log(alpha) + 0.5 * n * std::log(beta) -
         0.5 * n * std::log(M_PI) + symmetry;
}

double LogEvidenceGroups(double sse, const Eigen::VectorXd& group_ssx,
                         const Eigen::VectorXd& group_alpha, const Eigen::VectorXd& group_size,
                         double beta, double log_det_h, int error_count,
                         const std::vector<int>& layer_sizes,
                         const std::vector<int>& active_units) {
  // LogEvidence with alpha = 1 and ssX = 0 leaves out the prior's terms; they are added per group.
  const double rest =
      LogEvidence(sse, 0.0, 1.0, beta, log_det_h, 0, error_count, layer_sizes, active_units);
  return rest - group_alpha.dot(group_ssx) +
         0.5 * group_size.dot(group_alpha.array().log().matrix());
}

std::vector<int> ActiveHiddenUnits(const Network& net, const Eigen::MatrixXd& posterior_covariance,
                                   const Eigen::VectorXd& alpha_per_parameter) {
  const int N = net.ParameterCount();
  if (posterior_covariance.rows() != N || posterior_covariance.cols() != N ||
      alpha_per_parameter.size() != N)
    throw InputError("active units: covariance " + std::to_string(posterior_covariance.rows()) +
                     " x " + std::to_string(posterior_covariance.cols()) + " and " +
                     std::to_string(alpha_per_parameter.size()) + " alphas for " +
                     std::to_string(N) + " parameters");
  // gamma_i = 1 - alpha_i (H^-1)_ii, H^-1 = 2 A^-1 (trainbr.h: A^-1 = (2 H)^-1)
  auto gamma = [&](int i) {
    return 1.0 - 2.0 * alpha_per_parameter(i) * posterior_covariance(i, i);
  };
  std::vector<int> active;
  for (int l = 0; l + 1 < net.LayerCount(); ++l) {
    int count = 0;
    for (int r = 0; r < net.layer_sizes[l + 1]; ++r) {
      double g = gamma(net.BiasIndex(l, r));
      for (int c = 0; c < net.layer_sizes[l]; ++c) g += gamma(net.WeightIndex(l, r, c));
      for (int k = 0; k < net.layer_sizes[l + 2]; ++k) g += gamma(net.WeightIndex(l + 1, k, r));
      count += g >= kActiveUnitGamma ? 1 : 0;
    }
    active.push_back(count);
  }
  return active;
}

namespace {

void CheckTrainingData(const TrainingData& data, const Network& initial,
                       const TrainOptions& options) {
  options.Validate();
  initial.Validate("initial network");
  const Eigen::Index S = initial.OutputCount();
  const Eigen::Index Q = data.inputs.cols();
  if (Q < 1) throw InputError("training data: no samples");
  if (data.inputs.rows() != initial.InputCount())
    throw InputError("training data: " + std::to_string(data.inputs.rows()) +
                     " input rows, the network has " + std::to_string(initial.InputCount()) +
                     " inputs");
  if (data.targets.rows() != S || data.targets.cols() != Q)
    throw InputError("training data: targets are " + std::to_string(data.targets.rows()) + "x" +
                     std::to_string(data.targets.cols()) + ", expected " + std::to_string(S) + "x" +
                     std::to_string(Q));
  if (!data.inputs.allFinite() || !data.targets.allFinite())
    throw InputError("training data: NaN or infinity in the inputs or targets");
  if (data.target_scaling.size() != S)
    throw InputError("training data: target scaling has " +
                     std::to_string(data.target_scaling.size()) + " variables, expected " +
                     std::to_string(S));
}

}  // namespace

namespace {

// TrainOptions::ard: the weight groups (first-layer weights of input i -> i, all else -> R).
Eigen::VectorXi ArdGroups(const Network& net) {
  const int R = net.InputCount();
  Eigen::VectorXi group = Eigen::VectorXi::Constant(net.ParameterCount(), R);
  for (int r = 0; r < net.layer_sizes[1]; ++r)
    for (int i = 0; i < R; ++i) group(net.WeightIndex(0, r, i)) = i;
  return group;
}

Eigen::VectorXd GroupSums(const Eigen::VectorXi& group, int groups, const Eigen::VectorXd& v) {
  Eigen::VectorXd sum = Eigen::VectorXd::Zero(groups);
  for (Eigen::Index i = 0; i < v.size(); ++i) sum(group(i)) += v(i);
  return sum;
}

// H = beta J'J + diag(a) from the full J'J.
Eigen::MatrixXd ArdHessian(const Eigen::MatrixXd& jj, double beta, const Eigen::VectorXd& a) {
  Eigen::MatrixXd h = beta * jj;
  h.diagonal() += a;
  return h;
}

// alpha_g and beta of TrainOptions::ard after a step (MacKay 1992, one alpha per group).
struct ArdHyper {
  Eigen::VectorXd alpha;  ///< per group
  double beta = 0;
  double gamma = 0;  ///< sum of gamma_g
};

// One re-estimation at weights w: gamma_g = N_g - alpha_g trace_g(H^-1), alpha_g = gamma_g /
// (2 ssX_g), beta = (n - sum gamma_g) / (2 ssE). A group whose ssX_g is 0 or whose gamma_g is
// not positive (only by rounding: H >= diag(alpha) makes gamma_g >= 0) goes to kArdAlphaMax, as
// does any alpha_g above it. Returns "" and updates `h`, or a reason and leaves `h` as it was.
std::string ReestimateArd(const Eigen::MatrixXd& jj, double sse, const Eigen::VectorXd& w,
                          const Eigen::VectorXi& group, const Eigen::VectorXd& group_size, double n,
                          ArdHyper* h) {
  const auto G = h->alpha.size();
  const Eigen::LLT<Eigen::MatrixXd> llt(ArdHessian(jj, h->beta, h->alpha(group)));
  if (llt.info() != Eigen::Success) return "H = beta J'J + diag(alpha_g) not positive definite";
  const Eigen::MatrixXd h_inv = llt.solve(Eigen::MatrixXd::Identity(w.size(), w.size()));
  const Eigen::VectorXd gamma =
      (group_size - h->alpha.cwiseProduct(GroupSums(group, G, h_inv.diagonal()))).cwiseMax(0.0);
  const Eigen::VectorXd ssx = GroupSums(group, G, w.cwiseAbs2());
  Eigen::VectorXd alpha(G);
  for (Eigen::Index g = 0; g < G; ++g)
    alpha(g) = ssx(g) == 0 || !(gamma(g) > 0) ? kArdAlphaMax
                                              : std::min(gamma(g) / (2 * ssx(g)), kArdAlphaMax);
  const double beta = sse == 0 ? 1.0 : (n - gamma.sum()) / (2 * sse);
  if (!alpha.allFinite() || !std::isfinite(beta) || !(beta > 0))
    return "gamma = " + MessageNumber(gamma.sum()) + ", beta = " + MessageNumber(beta) +
           " (kept the last finite alpha_g, beta)";
  *h = {alpha, beta, gamma.sum()};
  return "";
}

// The Laplace approximation of the ARD stage at its final weights: ln det H and (2 H)^-1 from a
// Cholesky factor of H = beta J'J + diag(alpha_g(i)) (accurate also with alpha_g at
// kArdAlphaMax); through eigenvalues clamped at the smallest alpha_g (H >= diag(alpha_g(i)) bounds
// them from below) only if the factor fails.
double ArdLaplace(const Eigen::MatrixXd& h, double min_alpha, Eigen::MatrixXd* covariance) {
  const Eigen::Index N = h.rows();
  const Eigen::LLT<Eigen::MatrixXd> llt(h);
  if (llt.info() == Eigen::Success) {
    *covariance = 0.5 * llt.solve(Eigen::MatrixXd::Identity(N, N));
    *covariance = 0.5 * (*covariance + covariance->transpose()).eval();
    return 2 * Eigen::MatrixXd(llt.matrixL()).diagonal().array().log().sum();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(h);
  const Eigen::VectorXd h_eig = eig.eigenvalues().cwiseMax(min_alpha);
  const Eigen::MatrixXd& V = eig.eigenvectors();
  *covariance = V * (0.5 * h_eig.cwiseInverse()).asDiagonal() * V.transpose();
  *covariance = 0.5 * (*covariance + covariance->transpose()).eval();
  return h_eig.array().log().sum();
}

// The second stage of TrainOptions::ard, from trainbr's result `first` (nn/trainbr.h): one
// grouped re-estimation at trainbr's weights, then LM epochs in the weights form, each accepted
// step followed by a re-estimation. `steps` counts the accepted steps.
TrainResult RefineArd(const TrainingData& data, TrainResult first, const TrainOptions& options,
                      const EpochCallback& callback, int* steps) {
  Network& net = first.network;
  TrainSummary& sum = first.summary;
  const Eigen::VectorXi group = ArdGroups(net);
  const int G = net.InputCount() + 1;
  const Eigen::VectorXd group_size = GroupSums(group, G, Eigen::VectorXd::Ones(group.size()));
  const double n = static_cast<double>(data.targets.size());
  ArdHyper hyper{Eigen::VectorXd::Constant(G, sum.alpha), sum.beta, sum.gamma};
  Eigen::VectorXd w = net.GetParameters();
  Network trial = net;
  ForwardCache cache, trial_cache;
  net.Forward(data.inputs, &cache);
  Eigen::MatrixXd e = data.targets - cache.output(), J;
  double sse = SumSquares(e);
  ErrorJacobian(net, cache, &J);
  std::string degenerate = ReestimateArd(J.transpose() * J, sse, w, group, group_size, n, &hyper);
  Eigen::VectorXd a = hyper.alpha(group);
  double F = hyper.beta * sse + a.dot(w.cwiseAbs2());
  double mu = options.mu, gradient = 0;
  std::vector<double> after_step;
  const std::string first_message = sum.message;
  const int first_epochs = sum.epochs;
  *steps = 0;
  for (int epoch = 0;; ++epoch) {
    if (epoch > 0) ErrorJacobian(net, cache, &J);
    const Eigen::Map<const Eigen::VectorXd> e_flat(e.data(), e.size());
    const Eigen::MatrixXd jj = J.transpose() * J;
    const Eigen::VectorXd je = J.transpose() * e_flat;
    gradient = 2 * je.norm();
    sum.epochs = first_epochs + epoch;
    if (StopReached(options, epoch, sse, gradient, mu, after_step, degenerate, &sum)) break;
    EpochInfo info;
    info.epoch = epoch + 1;
    info.ard_stage = true;
    info.max_epochs = options.epochs;
    info.gradient = gradient;
    info.objective_before = F;
    const Eigen::VectorXd rhs = hyper.beta * je + a.cwiseProduct(w);
    bool accepted = false;
    for (; mu <= options.mu_max; mu *= options.mu_inc) {
      Eigen::MatrixXd shifted = ArdHessian(jj, hyper.beta, a);
      shifted.diagonal().array() += mu;
      const Eigen::LLT<Eigen::MatrixXd> llt(shifted);
      if (llt.info() != Eigen::Success) continue;
      const Eigen::VectorXd w2 = w - llt.solve(rhs);
      if (!w2.allFinite()) continue;
      trial.SetParameters(w2);
      trial.Forward(data.inputs, &trial_cache);
      const Eigen::MatrixXd e2 = data.targets - trial_cache.output();
      const double sse2 = SumSquares(e2), F2 = hyper.beta * sse2 + a.dot(w2.cwiseAbs2());
      if (F2 < F) {
        w = w2;
        std::swap(net, trial);
        std::swap(cache, trial_cache);
        e = e2;
        sse = sse2;
        F = F2;
        mu = std::max(mu * options.mu_dec, kMuFloor);
        accepted = true;
        ++*steps;
        break;
      }
    }
    info.step_accepted = accepted;
    info.objective_after_step = F;
    if (options.change > 0) after_step.push_back(F);
    if (accepted) {
      degenerate = ReestimateArd(jj, sse, w, group, group_size, n, &hyper);
      a = hyper.alpha(group);
      F = hyper.beta * sse + a.dot(w.cwiseAbs2());
    }
    info.objective = F;
    info.sse = sse;
    info.ssx = w.squaredNorm();
    info.gamma = hyper.gamma;
    info.alpha = hyper.alpha(G - 1);
    info.beta = hyper.beta;
    info.mu = mu;
    info.network = &net;
    if (callback) callback(info);
  }
  sum.message = first_message + "; ARD stage: " + sum.message;
  sum.final_cost = F;
  sum.sse = sse;
  sum.sum_squared_weights = w.squaredNorm();
  sum.gamma = hyper.gamma;
  sum.alpha = hyper.alpha(G - 1);
  sum.ard_alpha = hyper.alpha;
  sum.beta = hyper.beta;
  sum.mu = mu;
  sum.gradient = gradient;
  sum.rms_error_normalized =
      (e.array().square().rowwise().sum() / static_cast<double>(e.cols())).sqrt();
  sum.rms_error = sum.rms_error_normalized.cwiseProduct(data.target_scaling.HalfRange());
  // J is at the final weights: the loop ends right after computing it.
  const double log_det_h = ArdLaplace(ArdHessian(J.transpose() * J, hyper.beta, a),
                                      hyper.alpha.minCoeff(), &first.posterior_covariance);
  const Eigen::VectorXd final_alpha = hyper.alpha(group);
  sum.log_evidence = LogEvidenceGroups(
      sse, GroupSums(group, G, w.cwiseAbs2()), hyper.alpha, group_size, hyper.beta, log_det_h,
      static_cast<int>(n), net.layer_sizes,
      ActiveHiddenUnits(net, first.posterior_covariance, final_alpha));
  sum.noise_variance = 1.0 / (2.0 * hyper.beta);
  return first;
}

}  // namespace

TrainResult TrainBr(const TrainingData& data, const Network& initial, const TrainOptions& options,
                    const EpochCallback& callback) {
  CheckTrainingData(data, initial, options);
  const int S = initial.OutputCount();
  const Eigen::Index Q = data.inputs.cols();
  const bool bayes = options.regularization == Regularization::kBayesian;
  TrainResult result;
  result.network = initial;
  Network& net = result.network;
  Network trial_net = initial;
  const int N = net.ParameterCount();
  const double n = static_cast<double>(S) * static_cast<double>(Q);

  // The systems of the epoch: N x N (beta J'J + c I) or n x n (beta J J' + c I); see LinearSystem.
  const bool errors_form =
      options.linear_system == LinearSystem::kErrors ||
      (options.linear_system == LinearSystem::kAuto && static_cast<double>(S) * Q < N);
  const Eigen::Index M = errors_form ? S * Q : N;

  // Work arrays, allocated once. gram is jj = J'J (kWeights) or J J' (kErrors).
  Eigen::VectorXd w = net.GetParameters();
  Eigen::VectorXd w2(N), dw(N), rhs(M), je(N), jw(S * Q), y(M);
  Eigen::MatrixXd J, gram(M, M), A(M, M), e(S, Q), e2(S, Q);
  Eigen::VectorXd work(M), inv_diag(M);
  Eigen::MatrixXd Jt(N, S * Q);
  ForwardCache cache, trial_cache;

  net.Forward(data.inputs, &cache);
  e = data.targets - cache.output();
  double sse = SumSquares(e);
  double ssx = w.squaredNorm();
  double gamma = N, alpha = 0, beta = 1;
  if (bayes) {
    beta = sse == 0 ? 1.0 : (n - N) / (2 * sse);
    if (!(beta > 0)) beta = 1.0;
    alpha = ssx == 0 ? 1.0 : N / (2 * ssx);
  }
  double F = beta * sse + alpha * ssx;
  TrainSummary& sum = result.summary;
  sum.parameter_count = N;
  sum.error_count = static_cast<int>(n);
  sum.initial_cost = F;
  sum.initial_sse = sse;
  sum.regularization = options.regularization;
  double mu = options.mu;
  double gradient = 0;
  std::string degenerate_message;  // set when the alpha/beta update stops being finite
  std::vector<double> after_step;  // F right after each epoch's LM step (TrainOptions::change)

  for (int epoch = 0;; ++epoch) {
    ErrorJacobian(net, cache, &J);
    Eigen::Map<const Eigen::VectorXd> e_flat(e.data(), e.size());
    je.noalias() = J.transpose() * e_flat;
    if (errors_form) {
      ErrorGram(net, cache, J, &gram);
      jw.noalias() = J * w;
    } else {
      GramLower(J, &Jt, &gram);  // lower triangle only
    }
    gradient = 2 * je.norm();

    sum.epochs = epoch;
    if (StopReached(options, epoch, sse, gradient, mu, after_step, degenerate_message, &sum)) break;

    EpochInfo info;
    info.epoch = epoch + 1;
    info.max_epochs = options.epochs;
    info.objective_before = F;
    info.gradient = gradient;
    if (!errors_form) rhs = beta * je + alpha * w;
    bool accepted = false;
    double shift_accepted = 0;  // mu + alpha of the accepted step; A holds its factor
    while (mu <= options.mu_max) {
      const double c = mu + alpha;
      if (FactorShifted(gram, beta, c, &A, &inv_diag)) {
        if (errors_form) {
          // dw = -(alpha/c) w - beta J' K_c^-1 (e - (alpha/c) J w) (LinearSystem::kErrors).
          const double r = alpha / c;
          rhs = e_flat - r * jw;
          SolveFactored(A, inv_diag, rhs, &y);
          dw.noalias() = -beta * (J.transpose() * y);
          dw -= r * w;
        } else {
          SolveFactored(A, inv_diag, rhs, &dw);
          dw = -dw;
        }
        if (dw.allFinite()) {
          w2 = w + dw;
          trial_net.SetParameters(w2);
          trial_net.Forward(data.inputs, &trial_cache);
          e2 = data.targets - trial_cache.output();
          const double sse2 = SumSquares(e2);
          const double ssx2 = w2.squaredNorm();
          const double F2 = beta * sse2 + alpha * ssx2;
          if (F2 < F) {
            std::swap(w, w2);
            std::swap(net, trial_net);
            std::swap(cache, trial_cache);
            std::swap(e, e2);
            sse = sse2;
            ssx = ssx2;
            F = F2;
            shift_accepted = c;
            mu = std::max(mu * options.mu_dec, kMuFloor);
            accepted = true;
            break;
          }
        }
      }
      mu *= options.mu_inc;
    }
    info.step_accepted = accepted;
    info.objective_after_step = F;
    if (options.change > 0) after_step.push_back(F);
    if (accepted && bayes) {
      // gamma from the Gram matrix of this epoch and the old alpha, beta (REFERENCE.md
      // section 2): trace(H^-1) = ||L^-1||_F^2 for H = L L'; in the errors form
      // gamma = n - alpha trace(K_alpha^-1) (LinearSystem), so M - alpha trace covers both.
      // Once mu has fallen below rounding of alpha, mu + alpha == alpha and the accepted step's
      // factor is bit for bit the factor of this H: reuse it. An H that is not numerically
      // positive definite gives gamma = NaN, which ends the fit on the degenerate path below.
      bool factored = shift_accepted == alpha;
      if (!factored) factored = FactorShifted(gram, beta, alpha, &A, &inv_diag);
      const double gamma_new =
          factored ? static_cast<double>(M) - alpha * TraceOfInverse(A, inv_diag, &work)
                   : std::numeric_limits<double>::quiet_NaN();
      const double alpha_new = ssx == 0 ? 1.0 : gamma_new / (2 * ssx);
      const double beta_new = sse == 0 ? 1.0 : (n - gamma_new) / (2 * sse);
      if (std::isfinite(alpha_new) && alpha_new > 0 && std::isfinite(beta_new) && beta_new > 0) {
        gamma = gamma_new;
        alpha = alpha_new;
        beta = beta_new;
      } else {
        degenerate_message =
            "gamma = " + MessageNumber(gamma_new) + ", alpha = " + MessageNumber(alpha_new) +
            ", beta = (n - gamma)/(2 ssE) = " + MessageNumber(beta_new) +
            " at ssE = " + MessageNumber(sse) + " (kept the last finite alpha, beta)";
      }
      F = beta * sse + alpha * ssx;
    }
    info.objective = F;
    info.sse = sse;
    info.ssx = ssx;
    info.gamma = gamma;
    info.alpha = alpha;
    info.beta = beta;
    info.mu = mu;
    info.network = &net;
    if (callback) callback(info);
  }

  sum.final_cost = F;
  sum.sse = sse;
  sum.sum_squared_weights = ssx;
  sum.gamma = gamma;
  sum.alpha = alpha;
  sum.beta = beta;
  sum.mu = mu;
  sum.gradient = gradient;
  sum.rms_error_normalized = (e.array().square().rowwise().sum() / static_cast<double>(Q)).sqrt();
  sum.rms_error = sum.rms_error_normalized.cwiseProduct(data.target_scaling.HalfRange());
  if (bayes) {
    // Laplace approximation at the final weights (J is at the final w: the loop ended right
    // after computing it; in the weights form gram holds the lower triangle of its jj).
    // Through the eigenvalues of jj (clamped at 0) rather than a Cholesky factor, so that a
    // near-interpolating fit (beta ~ 1e8 or more, H badly conditioned) still gives a finite
    // log det and a positive semi-definite covariance.
    Eigen::MatrixXd jj(N, N);
    if (errors_form) {
      GramLower(J, &Jt, &jj);
    } else {
      jj = gram;
    }
    jj.triangularView<Eigen::StrictlyUpper>() = jj.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jj);
    const Eigen::VectorXd h_eig =
        (beta * eig.eigenvalues().cwiseMax(0.0)).array() + alpha;  // eigenvalues of H
    const double log_det_h = h_eig.array().log().sum();
    sum.noise_variance = 1.0 / (2.0 * beta);
    const Eigen::MatrixXd& V = eig.eigenvectors();
    result.posterior_covariance = V * (0.5 * h_eig.cwiseInverse()).asDiagonal() * V.transpose();
    // Exact symmetry (the product leaves rounding-level asymmetry).
    result.posterior_covariance =
        0.5 * (result.posterior_covariance + result.posterior_covariance.transpose()).eval();
    sum.log_evidence =
        LogEvidence(sse, ssx, alpha, beta, log_det_h, N, static_cast<int>(n), net.layer_sizes,
                    ActiveHiddenUnits(net, result.posterior_covariance,
                                      Eigen::VectorXd::Constant(N, alpha)));
  } else {
    sum.log_evidence = std::numeric_limits<double>::quiet_NaN();
    sum.noise_variance = std::numeric_limits<double>::quiet_NaN();
  }
  if (options.ard && bayes) {
    // MacKay's model comparison: the ARD stage is kept only when the data support it.
    int steps = 0;
    TrainResult ard = RefineArd(data, result, options, callback, &steps);
    const double margin = kArdEvidenceMargin * std::max(1.0, std::abs(sum.log_evidence));
    if (steps > 0 && ard.summary.log_evidence > sum.log_evidence + margin) return ard;
    sum.message += "; ARD stage not kept (" + std::to_string(steps) +
                   " accepted steps, log evidence " + MessageNumber(ard.summary.log_evidence) +
                   " against " + MessageNumber(sum.log_evidence) + ")";
  }
  return result;
}

RestartResult TrainBrRestarts(const TrainingData& data, const std::vector<int>& layer_sizes,
                              std::uint64_t seed, int restarts, const TrainOptions& options,
                              const std::function<void(int, const EpochInfo&)>& callback,
                              int threads) {
  if (restarts < 1) throw InputError("restarts = " + std::to_string(restarts) + ": must be >= 1");
  std::vector<TrainResult> results(static_cast<std::size_t>(restarts));
  std::mutex callback_mutex;
  ParallelFor(results.size(), threads, [&](std::size_t k) {
    Network net = Network::Zeros(layer_sizes);
    const std::uint64_t s = seed + static_cast<std::uint64_t>(k);
    InitNguyenWidrow(s, &net);
    EpochCallback cb;
    if (callback)
      cb = [&callback, &callback_mutex, k](const EpochInfo& info) {
        std::lock_guard<std::mutex> lock(callback_mutex);
        callback(static_cast<int>(k), info);
      };
    results[k] = TrainBr(data, net, options, cb);
    results[k].init_seed = s;
  });
  // Selection in seed order after all runs: the same result for any thread count.
  RestartResult out;
  const bool bayes = options.regularization == Regularization::kBayesian;
  for (int k = 0; k < restarts; ++k) {
    const TrainResult& r = results[static_cast<std::size_t>(k)];
    RestartRecord rec;
    rec.seed = r.init_seed;
    rec.log_evidence = r.summary.log_evidence;
    rec.sse = r.summary.sse;
    rec.gamma = r.summary.gamma;
    rec.epochs = r.summary.epochs;
    rec.termination = r.summary.termination;
    out.runs.push_back(rec);
    bool better = k == 0;
    if (!better) {
      const TrainSummary& best = results[static_cast<std::size_t>(out.best_index)].summary;
      if (bayes) {
        // A NaN evidence (should not happen with alpha, beta > 0) never wins.
        better = rec.log_evidence > best.log_evidence ||
                 (std::isnan(best.log_evidence) && !std::isnan(rec.log_evidence));
      } else {
        better = rec.sse < best.sse;
      }
    }
    if (better) out.best_index = k;
  }
  out.best = std::move(results[static_cast<std::size_t>(out.best_index)]);
  return out;
}

}  // namespace whirl::nn
