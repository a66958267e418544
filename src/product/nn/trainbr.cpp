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

// The figures both iterations (trainbr's and the ARD stage's) report after an epoch and at the
// end: F, ssE, ssX, gamma, alpha, beta, mu and the gradient 2 ||J'e||.
struct IterationFigures {
  double objective, sse, ssx, gamma, alpha, beta, mu, gradient;

  void FillEpochEnd(const Network* net, EpochInfo* info) const {
    info->objective = objective;
    info->sse = sse;
    info->ssx = ssx;
    info->gamma = gamma;
    info->alpha = alpha;
    info->beta = beta;
    info->mu = mu;
    info->network = net;
  }
  // With the RMS errors of the errors e (S x Q, normalized), also in original units.
  void FillSummaryEnd(const Eigen::MatrixXd& e, const MapMinMax& target_scaling,
                      TrainSummary* sum) const {
    sum->final_cost = objective;
    sum->sse = sse;
    sum->sum_squared_weights = ssx;
    sum->gamma = gamma;
    sum->alpha = alpha;
    sum->beta = beta;
    sum->mu = mu;
    sum->gradient = gradient;
    sum->rms_error_normalized =
        (e.array().square().rowwise().sum() / static_cast<double>(e.cols())).sqrt();
    sum->rms_error = sum->rms_error_normalized.cwiseProduct(target_scaling.HalfRange());
  }
};

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

// The LM iteration of TrainOptions::ard's second stage, in the weights form: F = beta ssE +
// sum_i a_i w_i^2 with a_i = alpha_g(i), each accepted step followed by a grouped re-estimation
// (ReestimateArd). Starts from trainbr's result with one re-estimation at its weights.
class ArdIteration {
 public:
  ArdIteration(const TrainingData& data, const TrainResult& first, const TrainOptions& options)
      : data_(data),
        options_(options),
        net_(first.network),
        trial_(first.network),
        group_(ArdGroups(net_)),
        G_(net_.InputCount() + 1),
        group_size_(GroupSums(group_, G_, Eigen::VectorXd::Ones(group_.size()))),
        n_(static_cast<double>(data.targets.size())),
        hyper_{Eigen::VectorXd::Constant(G_, first.summary.alpha), first.summary.beta,
               first.summary.gamma} {
    w_ = net_.GetParameters();
    net_.Forward(data.inputs, &cache_);
    e_ = data.targets - cache_.output();
    sse_ = SumSquares(e_);
    ErrorJacobian(net_, cache_, &J_);
    degenerate_ = ReestimateArd(J_.transpose() * J_, sse_, w_, group_, group_size_, n_, &hyper_);
    a_ = hyper_.alpha(group_);
    F_ = hyper_.beta * sse_ + a_.dot(w_.cwiseAbs2());
    mu_ = options.mu;
  }

  // J'J, J'e and the gradient 2 ||J'e|| at the current weights (J recomputed unless it is the
  // constructor's).
  void Linearize(bool jacobian_is_current) {
    if (!jacobian_is_current) ErrorJacobian(net_, cache_, &J_);
    const Eigen::Map<const Eigen::VectorXd> e_flat(e_.data(), e_.size());
    jj_ = J_.transpose() * J_;
    je_ = J_.transpose() * e_flat;
    gradient_ = 2 * je_.norm();
  }

  // One LM step: mu grows by mu_inc until F falls (the step is taken, mu shrinks by mu_dec) or mu
  // passes mu_max. Returns whether a step was taken.
  bool Step() {
    const Eigen::VectorXd rhs = hyper_.beta * je_ + a_.cwiseProduct(w_);
    for (; mu_ <= options_.mu_max; mu_ *= options_.mu_inc) {
      Eigen::MatrixXd shifted = ArdHessian(jj_, hyper_.beta, a_);
      shifted.diagonal().array() += mu_;
      const Eigen::LLT<Eigen::MatrixXd> llt(shifted);
      if (llt.info() != Eigen::Success) continue;
      const Eigen::VectorXd w2 = w_ - llt.solve(rhs);
      if (!w2.allFinite()) continue;
      trial_.SetParameters(w2);
      trial_.Forward(data_.inputs, &trial_cache_);
      const Eigen::MatrixXd e2 = data_.targets - trial_cache_.output();
      const double sse2 = SumSquares(e2), F2 = hyper_.beta * sse2 + a_.dot(w2.cwiseAbs2());
      if (F2 < F_) {
        w_ = w2;
        std::swap(net_, trial_);
        std::swap(cache_, trial_cache_);
        e_ = e2;
        sse_ = sse2;
        F_ = F2;
        mu_ = std::max(mu_ * options_.mu_dec, kMuFloor);
        return true;
      }
    }
    return false;
  }

  // The grouped re-estimation after an accepted step, with this epoch's J'J; updates F.
  void Reestimate() {
    degenerate_ = ReestimateArd(jj_, sse_, w_, group_, group_size_, n_, &hyper_);
    a_ = hyper_.alpha(group_);
    F_ = hyper_.beta * sse_ + a_.dot(w_.cwiseAbs2());
  }

  // The values an epoch reports after its step and update (alpha: the group of the other weights).
  void FillEpochEnd(EpochInfo* info) const { Figures().FillEpochEnd(&net_, info); }

  // The summary at the final weights (J is at them: the loop ends right after Linearize) with the
  // Laplace approximation of the grouped prior (ArdLaplace, LogEvidenceGroups).
  void Finish(TrainResult* result) {
    TrainSummary& sum = result->summary;
    Figures().FillSummaryEnd(e_, data_.target_scaling, &sum);
    sum.ard_alpha = hyper_.alpha;
    const double log_det_h = ArdLaplace(ArdHessian(J_.transpose() * J_, hyper_.beta, a_),
                                        hyper_.alpha.minCoeff(), &result->posterior_covariance);
    const Eigen::VectorXd final_alpha = hyper_.alpha(group_);
    sum.log_evidence =
        LogEvidenceGroups(sse_, GroupSums(group_, G_, w_.cwiseAbs2()), hyper_.alpha, group_size_,
                          hyper_.beta, log_det_h, static_cast<int>(n_), net_.layer_sizes,
                          ActiveHiddenUnits(net_, result->posterior_covariance, final_alpha));
    sum.noise_variance = 1.0 / (2.0 * hyper_.beta);
    result->network = std::move(net_);
  }

  double sse() const { return sse_; }
  double gradient() const { return gradient_; }
  double mu() const { return mu_; }
  double objective() const { return F_; }
  const std::string& degenerate() const { return degenerate_; }

 private:
  // alpha: the group of the weights that are not an input's.
  IterationFigures Figures() const {
    return {F_,          sse_, w_.squaredNorm(), hyper_.gamma, hyper_.alpha(G_ - 1),
            hyper_.beta, mu_,  gradient_};
  }

  const TrainingData& data_;
  const TrainOptions& options_;
  Network net_, trial_;
  const Eigen::VectorXi group_;
  const int G_;  // groups: one per input, then all other weights
  const Eigen::VectorXd group_size_;
  const double n_;  // errors
  ArdHyper hyper_;
  ForwardCache cache_, trial_cache_;
  Eigen::MatrixXd e_, J_, jj_;
  Eigen::VectorXd w_, a_, je_;
  double sse_ = 0, F_ = 0, mu_ = 0, gradient_ = 0;
  std::string degenerate_;  // ReestimateArd's reason when its update was not finite
};

// The second stage of TrainOptions::ard, from trainbr's result `first` (nn/trainbr.h): one
// grouped re-estimation at trainbr's weights, then LM epochs in the weights form, each accepted
// step followed by a re-estimation. `steps` counts the accepted steps.
TrainResult RefineArd(const TrainingData& data, TrainResult first, const TrainOptions& options,
                      const EpochCallback& callback, int* steps) {
  TrainSummary& sum = first.summary;
  ArdIteration it(data, first, options);
  std::vector<double> after_step;
  const std::string first_message = sum.message;
  const int first_epochs = sum.epochs;
  *steps = 0;
  for (int epoch = 0;; ++epoch) {
    it.Linearize(epoch == 0);
    sum.epochs = first_epochs + epoch;
    if (StopReached(options, epoch, it.sse(), it.gradient(), it.mu(), after_step, it.degenerate(),
                    &sum))
      break;
    EpochInfo info;
    info.epoch = epoch + 1;
    info.ard_stage = true;
    info.max_epochs = options.epochs;
    info.gradient = it.gradient();
    info.objective_before = it.objective();
    info.step_accepted = it.Step();
    if (info.step_accepted) ++*steps;
    info.objective_after_step = it.objective();
    if (options.change > 0) after_step.push_back(it.objective());
    if (info.step_accepted) it.Reestimate();
    it.FillEpochEnd(&info);
    if (callback) callback(info);
  }
  sum.message = first_message + "; ARD stage: " + sum.message;
  it.Finish(&first);
  return first;
}

// trainbr's iteration (nn/trainbr.h): Levenberg-Marquardt steps on F = beta ssE + alpha ssX with
// the re-estimation of alpha and beta after each accepted step, on work arrays allocated once.
// The systems of an epoch are N x N (beta J'J + c I, the weights form) or n x n (beta J J' + c I,
// the errors form); see LinearSystem. gram holds J'J (lower triangle) or J J'.
class BrIteration {
 public:
  BrIteration(const TrainingData& data, const Network& initial, const TrainOptions& options)
      : data_(data),
        options_(options),
        bayes_(options.regularization == Regularization::kBayesian),
        net_(initial),
        trial_net_(initial) {
    const int S = initial.OutputCount();
    const Eigen::Index Q = data.inputs.cols();
    N_ = net_.ParameterCount();
    n_ = static_cast<double>(S) * static_cast<double>(Q);
    errors_form_ =
        options.linear_system == LinearSystem::kErrors ||
        (options.linear_system == LinearSystem::kAuto && static_cast<double>(S) * Q < N_);
    M_ = errors_form_ ? S * Q : N_;
    w_ = net_.GetParameters();
    for (Eigen::VectorXd* v : {&w2_, &dw_, &je_}) v->resize(N_);
    for (Eigen::VectorXd* v : {&rhs_, &y_, &work_, &inv_diag_}) v->resize(M_);
    jw_.resize(S * Q);
    gram_.resize(M_, M_);
    A_.resize(M_, M_);
    e_.resize(S, Q);
    e2_.resize(S, Q);
    Jt_.resize(N_, S * Q);
    net_.Forward(data.inputs, &cache_);
    e_ = data.targets - cache_.output();
    sse_ = SumSquares(e_);
    ssx_ = w_.squaredNorm();
    gamma_ = N_;
    if (bayes_) {  // the initial alpha and beta (nn/trainbr.h, step 1)
      beta_ = sse_ == 0 ? 1.0 : (n_ - N_) / (2 * sse_);
      if (!(beta_ > 0)) beta_ = 1.0;
      alpha_ = ssx_ == 0 ? 1.0 : N_ / (2 * ssx_);
    }
    F_ = beta_ * sse_ + alpha_ * ssx_;
    mu_ = options.mu;
  }

  // J, J'e, the Gram matrix (and J w in the errors form) and the gradient 2 ||J'e|| at the current
  // weights.
  void Linearize() {
    ErrorJacobian(net_, cache_, &J_);
    Eigen::Map<const Eigen::VectorXd> e_flat(e_.data(), e_.size());
    je_.noalias() = J_.transpose() * e_flat;
    if (errors_form_) {
      ErrorGram(net_, cache_, J_, &gram_);
      jw_.noalias() = J_ * w_;
    } else {
      GramLower(J_, &Jt_, &gram_);  // lower triangle only
    }
    gradient_ = 2 * je_.norm();
  }

  // One LM step with the current alpha and beta: mu grows by mu_inc until F falls (the step is
  // taken and mu shrinks by mu_dec) or mu passes mu_max. Returns whether a step was taken.
  bool Step() {
    Eigen::Map<const Eigen::VectorXd> e_flat(e_.data(), e_.size());
    if (!errors_form_) rhs_ = beta_ * je_ + alpha_ * w_;
    shift_accepted_ = 0;
    while (mu_ <= options_.mu_max) {
      const double c = mu_ + alpha_;
      if (FactorShifted(gram_, beta_, c, &A_, &inv_diag_)) {
        if (errors_form_) {
          // dw = -(alpha/c) w - beta J' K_c^-1 (e - (alpha/c) J w) (LinearSystem::kErrors).
          const double r = alpha_ / c;
          rhs_ = e_flat - r * jw_;
          SolveFactored(A_, inv_diag_, rhs_, &y_);
          dw_.noalias() = -beta_ * (J_.transpose() * y_);
          dw_ -= r * w_;
        } else {
          SolveFactored(A_, inv_diag_, rhs_, &dw_);
          dw_ = -dw_;
        }
        if (dw_.allFinite() && TryWeights(c)) return true;
      }
      mu_ *= options_.mu_inc;
    }
    return false;
  }

  // Re-estimates gamma, alpha and beta from this epoch's Gram matrix and the old alpha, beta
  // (MacKay 1992; Foresee and Hagan 1997) and updates F. Returns "" or, when the update is not
  // finite and positive, the reason (the last finite alpha and beta are kept).
  std::string Reestimate() {
    // trace(H^-1) = ||L^-1||_F^2 for H = L L'; in the errors form gamma = n - alpha
    // trace(K_alpha^-1) (LinearSystem), so M - alpha trace covers both. Once mu has fallen below
    // rounding of alpha, mu + alpha == alpha and the accepted step's factor is bit for bit the
    // factor of this H: reuse it. An H that is not numerically positive definite gives
    // gamma = NaN, which ends the fit on the degenerate path.
    std::string degenerate;
    bool factored = shift_accepted_ == alpha_;
    if (!factored) factored = FactorShifted(gram_, beta_, alpha_, &A_, &inv_diag_);
    const double gamma_new =
        factored ? static_cast<double>(M_) - alpha_ * TraceOfInverse(A_, inv_diag_, &work_)
                 : std::numeric_limits<double>::quiet_NaN();
    const double alpha_new = ssx_ == 0 ? 1.0 : gamma_new / (2 * ssx_);
    const double beta_new = sse_ == 0 ? 1.0 : (n_ - gamma_new) / (2 * sse_);
    if (std::isfinite(alpha_new) && alpha_new > 0 && std::isfinite(beta_new) && beta_new > 0) {
      gamma_ = gamma_new;
      alpha_ = alpha_new;
      beta_ = beta_new;
    } else {
      degenerate = "gamma = " + MessageNumber(gamma_new) + ", alpha = " + MessageNumber(alpha_new) +
                   ", beta = (n - gamma)/(2 ssE) = " + MessageNumber(beta_new) +
                   " at ssE = " + MessageNumber(sse_) + " (kept the last finite alpha, beta)";
    }
    F_ = beta_ * sse_ + alpha_ * ssx_;
    return degenerate;
  }

  // The values an epoch reports after its step and update.
  void FillEpochEnd(EpochInfo* info) const { Figures().FillEpochEnd(&net_, info); }

  // The summary at the final weights (J is at them: the loop ends right after Linearize) and, with
  // Bayesian regularization, the Laplace approximation: log evidence and posterior covariance.
  void Finish(TrainResult* result) {
    TrainSummary& sum = result->summary;
    Figures().FillSummaryEnd(e_, data_.target_scaling, &sum);
    if (bayes_) {
      Laplace(result);
    } else {
      sum.log_evidence = std::numeric_limits<double>::quiet_NaN();
      sum.noise_variance = std::numeric_limits<double>::quiet_NaN();
    }
    result->network = std::move(net_);
  }

  double sse() const { return sse_; }
  double gradient() const { return gradient_; }
  double mu() const { return mu_; }
  double objective() const { return F_; }
  int parameter_count() const { return N_; }
  double error_count() const { return n_; }

 private:
  IterationFigures Figures() const {
    return {F_, sse_, ssx_, gamma_, alpha_, beta_, mu_, gradient_};
  }

  // Evaluates w + dw; takes it when F falls (c = mu + alpha of the step, whose factor A holds).
  bool TryWeights(double c) {
    w2_ = w_ + dw_;
    trial_net_.SetParameters(w2_);
    trial_net_.Forward(data_.inputs, &trial_cache_);
    e2_ = data_.targets - trial_cache_.output();
    const double sse2 = SumSquares(e2_);
    const double ssx2 = w2_.squaredNorm();
    const double F2 = beta_ * sse2 + alpha_ * ssx2;
    if (!(F2 < F_)) return false;
    std::swap(w_, w2_);
    std::swap(net_, trial_net_);
    std::swap(cache_, trial_cache_);
    std::swap(e_, e2_);
    sse_ = sse2;
    ssx_ = ssx2;
    F_ = F2;
    shift_accepted_ = c;
    mu_ = std::max(mu_ * options_.mu_dec, kMuFloor);
    return true;
  }

  // Through the eigenvalues of J'J (clamped at 0) rather than a Cholesky factor, so that a
  // near-interpolating fit (beta ~ 1e8 or more, H badly conditioned) still gives a finite log det
  // and a positive semi-definite covariance. In the weights form gram holds J'J's lower triangle.
  void Laplace(TrainResult* result) {
    TrainSummary& sum = result->summary;
    Eigen::MatrixXd jj(N_, N_);
    if (errors_form_) {
      GramLower(J_, &Jt_, &jj);
    } else {
      jj = gram_;
    }
    jj.triangularView<Eigen::StrictlyUpper>() = jj.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jj);
    const Eigen::VectorXd h_eig =
        (beta_ * eig.eigenvalues().cwiseMax(0.0)).array() + alpha_;  // eigenvalues of H
    const double log_det_h = h_eig.array().log().sum();
    sum.noise_variance = 1.0 / (2.0 * beta_);
    const Eigen::MatrixXd& V = eig.eigenvectors();
    result->posterior_covariance = V * (0.5 * h_eig.cwiseInverse()).asDiagonal() * V.transpose();
    // Exact symmetry (the product leaves rounding-level asymmetry).
    result->posterior_covariance =
        0.5 * (result->posterior_covariance + result->posterior_covariance.transpose()).eval();
    sum.log_evidence = LogEvidence(sse_, ssx_, alpha_, beta_, log_det_h, N_, static_cast<int>(n_),
                                   net_.layer_sizes,
                                   ActiveHiddenUnits(net_, result->posterior_covariance,
                                                     Eigen::VectorXd::Constant(N_, alpha_)));
  }

  const TrainingData& data_;
  const TrainOptions& options_;
  const bool bayes_;
  bool errors_form_ = false;
  int N_ = 0;           // parameters
  double n_ = 0;        // errors, S Q
  Eigen::Index M_ = 0;  // size of the epoch's systems
  Network net_, trial_net_;
  Eigen::VectorXd w_, w2_, dw_, rhs_, je_, jw_, y_, work_, inv_diag_;
  Eigen::MatrixXd J_, gram_, A_, e_, e2_, Jt_;
  ForwardCache cache_, trial_cache_;
  double sse_ = 0, ssx_ = 0, gamma_ = 0, alpha_ = 0, beta_ = 1, F_ = 0, mu_ = 0, gradient_ = 0;
  double shift_accepted_ = 0;  // mu + alpha of the accepted step; A holds its factor
};

// TrainOptions::ard after trainbr: MacKay's model comparison keeps the ARD stage only when the
// data support it (a log evidence above trainbr's by kArdEvidenceMargin).
TrainResult KeepArdIfSupported(const TrainingData& data, TrainResult result,
                               const TrainOptions& options, const EpochCallback& callback) {
  TrainSummary& sum = result.summary;
  int steps = 0;
  TrainResult ard = RefineArd(data, result, options, callback, &steps);
  const double margin = kArdEvidenceMargin * std::max(1.0, std::abs(sum.log_evidence));
  if (steps > 0 && ard.summary.log_evidence > sum.log_evidence + margin) return ard;
  sum.message += "; ARD stage not kept (" + std::to_string(steps) +
                 " accepted steps, log evidence " + MessageNumber(ard.summary.log_evidence) +
                 " against " + MessageNumber(sum.log_evidence) + ")";
  return result;
}

}  // namespace

TrainResult TrainBr(const TrainingData& data, const Network& initial, const TrainOptions& options,
                    const EpochCallback& callback) {
  CheckTrainingData(data, initial, options);
  const bool bayes = options.regularization == Regularization::kBayesian;
  BrIteration it(data, initial, options);
  TrainResult result;
  TrainSummary& sum = result.summary;
  sum.parameter_count = it.parameter_count();
  sum.error_count = static_cast<int>(it.error_count());
  sum.initial_cost = it.objective();
  sum.initial_sse = it.sse();
  sum.regularization = options.regularization;
  std::string degenerate_message;  // set when the alpha/beta update stops being finite
  std::vector<double> after_step;  // F right after each epoch's LM step (TrainOptions::change)
  for (int epoch = 0;; ++epoch) {
    it.Linearize();
    sum.epochs = epoch;
    if (StopReached(options, epoch, it.sse(), it.gradient(), it.mu(), after_step,
                    degenerate_message, &sum))
      break;
    EpochInfo info;
    info.epoch = epoch + 1;
    info.max_epochs = options.epochs;
    info.objective_before = it.objective();
    info.gradient = it.gradient();
    info.step_accepted = it.Step();
    info.objective_after_step = it.objective();
    if (options.change > 0) after_step.push_back(it.objective());
    if (info.step_accepted && bayes) {
      std::string degenerate = it.Reestimate();
      if (!degenerate.empty()) degenerate_message = std::move(degenerate);
    }
    it.FillEpochEnd(&info);
    if (callback) callback(info);
  }
  it.Finish(&result);
  if (options.ard && bayes) return KeepArdIfSupported(data, std::move(result), options, callback);
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
