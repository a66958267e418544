#pragma once
// Bayesian-regularized Levenberg-Marquardt training, MATLAB `trainbr` (MathWorks documentation;
// MacKay, "Bayesian interpolation", Neural Computation 4(3) 1992; Foresee & Hagan, "Gauss-Newton
// approximation to Bayesian learning", ICNN 1997).
//
// Notation (MATLAB's, used in every field below):
//   N = number of weights and biases (50 for 5-6-2), n = number of target elements (S outputs x
//   Q samples), e = t - y in the NORMALIZED target space (mapminmax), J = de/dw,
//   ssE = e'e, ssX = w'w, objective F(w) = beta * ssE + alpha * ssX.
// MATLAB's alpha and beta are half of MacKay's: F = beta ssE + alpha ssX equals MacKay's
// M(w) = beta_M E_D + alpha_M E_W with E_D = ssE / 2, E_W = ssX / 2, beta_M = 2 beta,
// alpha_M = 2 alpha. So the noise variance (normalized units) is sigma_nu^2 = 1 / beta_M =
// 1 / (2 beta) = ssE / (n - gamma) at the re-estimated beta, and the Gauss-Newton posterior
// covariance of w is A^-1 = (beta_M J'J + alpha_M I)^-1 = (2 H)^-1 with H = beta J'J + alpha I
// (MacKay 1992 eqs. 2.8-2.10 and 4.3; Foresee & Hagan eqs. 11-13).
//
// Algorithm, per epoch (MathWorks' trainbr documentation, to the letter):
//   1. at the current w: ssE, J, je = J'e, jj = J'J, gradient = 2 ||J'e||.
//   2. stop if ssE <= goal (kGoalMet), epoch == epochs (kMaxEpochs), gradient <= min_grad
//      (kMinGradient), mu >= mu_max (kMaxMu), tested in that order; then, only when
//      options.change > 0 (R brnn's rule, not MATLAB's), the objective stalled
//      (kObjectiveStalled, see TrainOptions::change).
//   3. while mu <= mu_max: dw = -(beta jj + (mu + alpha) I)^-1 (beta je + alpha w);
//      accept if dw is finite and beta ssE(w + dw) + alpha ||w + dw||^2 < F(w), then
//      mu = max(mu * mu_dec, 1e-20); otherwise mu = mu * mu_inc.
//   4. after an accepted step, with the OLD alpha, beta and the jj of step 1:
//      gamma = N - alpha trace((beta jj + alpha I)^-1); alpha = gamma / (2 ssX);
//      beta = (n - gamma) / (2 ssE) (each set to 1 when its denominator is 0); F recomputed.
// Initialization: gamma = N; beta = (n - N) / (2 ssE), set to 1 when ssE = 0 or the value is not
// positive (with 20 samples and 2 outputs, n - N = 40 - 50 < 0, so beta starts at 1);
// alpha = N / (2 ssX) (1 when ssX = 0).
#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "nn/network.h"

namespace whirl::nn {

enum class Regularization {
  kBayesian,  ///< trainbr: alpha, beta re-estimated by the evidence framework (default)
  kNone,      ///< plain Levenberg-Marquardt (trainlm): alpha = 0, beta = 1 fixed, F = ssE
};

enum class TrainTermination {
  kGoalMet,      ///< ssE <= goal
  kMaxEpochs,    ///< epoch == epochs
  kMinGradient,  ///< gradient = 2 ||J'e|| <= min_grad
  kMaxMu,        ///< mu >= mu_max: no step decreased F any more (trainbr's usual ending)
  /// Not in MATLAB: the alpha/beta update gave a non-finite or non-positive value (ssE
  /// underflowed because the network interpolates the data, gamma -> n; possible when N > n).
  /// Training stops with the last finite alpha, beta. Tested first, at the next epoch.
  kInterpolation,
  /// Not in MATLAB; R brnn's rule (TrainOptions::change): the objective after the LM step changed
  /// by less than `change` between each of the last 4 epochs. Tested last.
  kObjectiveStalled,
};
std::string ToString(TrainTermination t);                 ///< "goal_met", "max_epochs", ...
TrainTermination ParseTermination(const std::string& s);  ///< inverse; InputError otherwise
std::string ToString(Regularization r);                   ///< "bayesian", "none"
Regularization ParseRegularization(const std::string& s);

/// Which n x n or N x N systems carry the LM steps and gamma. Both give the same step and gamma
/// (exact algebra, results agree to rounding):
///   kWeights: H_c = beta J'J + c I (N x N, c = mu + alpha) by Cholesky; dw = -H_c^-1 (beta je +
///             alpha w); gamma = N - alpha trace(H_alpha^-1). MATLAB's form.
///   kErrors:  K_c = beta J J' + c I (n x n) by Cholesky, through the push-through identity
///             H_c^-1 J' = J' K_c^-1 and Woodbury: dw = -(alpha/c) w - beta J' K_c^-1 (e -
///             (alpha/c) J w), and, since H_alpha has the eigenvalues of K_alpha plus N - n times
///             alpha, gamma = n - alpha trace(K_alpha^-1).
///   kAuto:    kErrors when n < N (few samples: 20 samples x 2 outputs = 40 < 50 weights, about
///             half the work per factorization), otherwise kWeights.
/// With one hidden layer J J' is assembled from its structure (nn::ErrorGram), not from J.
enum class LinearSystem { kAuto, kWeights, kErrors };

/// MATLAB trainbr defaults (net.trainParam).
struct TrainOptions {
  int epochs = 1000;       ///< maximum number of epochs (accepted or failed LM loops)
  double goal = 0.0;       ///< stop when ssE (normalized) <= goal
  double mu = 0.005;       ///< initial Marquardt damping mu
  double mu_dec = 0.1;     ///< mu factor after an accepted step (in (0, 1))
  double mu_inc = 10.0;    ///< mu factor after a rejected step (> 1)
  double mu_max = 1e10;    ///< stop when mu reaches this
  double min_grad = 1e-7;  ///< stop when 2 ||J'e|| <= min_grad
  /// R brnn's stopping rule (Perez-Rodriguez et al. 2013, brnn's `change`, default there 0.001;
  /// not in MATLAB, 0 = off, MATLAB's trainbr). With F_e the objective beta ssE + alpha ssX right
  /// after epoch e's LM step (EpochInfo::objective_after_step, the alpha, beta of that epoch):
  /// stop before epoch e + 1 when e >= 4 and max(|F_e - F_e-1|, |F_e-1 - F_e-2|, |F_e-2 - F_e-3|)
  /// < change (kObjectiveStalled). F is dimensionless (normalized targets), about n / 2 near
  /// the evidence optimum (beta ssE + alpha ssX -> (n - gamma) / 2 + gamma / 2).
  double change = 0.0;
  Regularization regularization = Regularization::kBayesian;
  /// How the epoch's linear systems are solved (same algorithm, results agree to rounding; not
  /// stored in model files). See LinearSystem.
  LinearSystem linear_system = LinearSystem::kAuto;
  /// Automatic relevance determination (MacKay 1994/1995; not in MATLAB; `whirl train
  /// --ard`). After trainbr has stopped, training continues from its weights, alpha and beta
  /// with one weight-decay coefficient per group: the first-layer weights from input i (one
  /// group per input) and all other weights and biases (one group), so
  ///   F = beta ssE + sum_g alpha_g ssX_g,  H = beta J'J + diag(alpha_g(i)),
  /// LM steps dw = -(H + mu I)^-1 (beta J'e + alpha_g(i) w_i) (the weights form). The groups are
  /// re-estimated once at trainbr's weights and after each accepted step:
  /// gamma_g = N_g - alpha_g trace_g(H^-1), alpha_g = gamma_g / (2 ssX_g) (capped at
  /// kArdAlphaMax, as is a group with gamma_g <= 0: an input the data do not support is switched
  /// off), beta = (n - sum gamma_g) / (2 ssE); the same stopping rules (epochs, change, ...) with
  /// the epoch count starting again (EpochInfo::ard_stage). Why two stages: the input groups
  /// are judged only after the network has learned something. The ARD result is kept only when
  /// at least one ARD step was accepted and its log evidence (LogEvidenceGroups, at the most
  /// probable alpha_g and beta) exceeds trainbr's by more than kArdEvidenceMargin (relative);
  /// then TrainSummary::ard_alpha holds the alpha_g, otherwise trainbr's result stands,
  /// ard_alpha stays empty and the message says why. The comparison leaves out the Occam
  /// factors of the extra hyperparameters (MacKay 1992 section 4: about ln(sigma_ln_alpha /
  /// range) per alpha_g), which would charge ARD for its G - 1 extra alphas: it guards against
  /// an ARD optimum worse than trainbr's, not against over-fitted hyperparameters; whether ARD
  /// helps is measured in scripts/bench_peers.sh (docs/network.md). Bayesian only.
  bool ard = false;

  /// Throws InputError naming the option, its value and the rule.
  void Validate() const;
};

/// The measure of TrainOptions::change: max |F_i - F_i-1| over the last 3 consecutive
/// differences of `after_step` (objectives after each epoch's step, oldest first); +infinity with
/// fewer than 4 values.
double ObjectiveSpread(const std::vector<double>& after_step);

/// What the per-epoch callback sees after each epoch's LM loop.
struct EpochInfo {
  int epoch = 0;                    ///< 1-based number of the epoch just finished
  bool ard_stage = false;           ///< TrainOptions::ard's second stage (epochs count from 1 again)
  int max_epochs = 0;               ///< options.epochs
  bool step_accepted = false;       ///< false when mu passed mu_max without a decrease
  double objective_before = 0;      ///< F(w) at the start of the epoch
  double objective_after_step = 0;  ///< F(w + dw) with the SAME alpha, beta (< objective_before)
  double objective = 0;             ///< F after the alpha/beta update
  double sse = 0;                   ///< ssE after the step (normalized)
  double ssx = 0;                   ///< ssX after the step
  double gamma = 0, alpha = 0, beta = 0;  ///< after the update
  double mu = 0;                          ///< after the LM loop
  double gradient = 0;                    ///< 2 ||J'e|| at the start of the epoch
  const Network* network = nullptr;       ///< the weights after the epoch (valid in the call)
};
using EpochCallback = std::function<void(const EpochInfo&)>;

/// Training set in the normalized space, one sample per column.
struct TrainingData {
  Eigen::MatrixXd inputs;    ///< R x Q, mapminmax-normalized
  Eigen::MatrixXd targets;   ///< S x Q, mapminmax-normalized
  MapMinMax target_scaling;  ///< only to report RMS errors in original units
};

struct TrainSummary {
  int epochs = 0;                        ///< completed epochs
  int parameter_count = 0;               ///< N
  int error_count = 0;                   ///< n = S * Q
  double initial_cost = 0;               ///< F at the initial weights with the initial alpha, beta
  double final_cost = 0;                 ///< F at the final weights with the final alpha, beta
  double initial_sse = 0;                ///< ssE at the initial weights (normalized)
  double sse = 0;                        ///< ssE at the final weights (normalized)
  Eigen::VectorXd rms_error;             ///< per output sqrt(mean e^2), original units
  Eigen::VectorXd rms_error_normalized;  ///< per output, normalized units
  double sum_squared_weights = 0;        ///< ssX = w'w at the final weights
  double gamma = 0;                      ///< effective number of parameters, in (0, N]
  double alpha = 0;                      ///< weight-decay coefficient of F (MATLAB convention)
  double beta = 0;                       ///< data coefficient of F (MATLAB convention)
  double mu = 0;                         ///< final Marquardt damping
  double gradient = 0;                   ///< 2 ||J'e|| at the final weights
  /// ln P(D | alpha, beta) of the final network (see LogEvidence); NaN without regularization.
  double log_evidence = 0;
  /// sigma_nu^2 = 1 / (2 beta), normalized units; NaN without regularization.
  double noise_variance = 0;
  Regularization regularization = Regularization::kBayesian;
  TrainTermination termination = TrainTermination::kMaxEpochs;
  std::string message;  ///< the reason with the numbers it compared
  /// TrainOptions::ard: alpha_g per input (in input order), then the group of all other weights
  /// (alpha above is that last one); epochs counts both stages. Empty without ARD or when the
  /// evidence did not keep the ARD stage.
  Eigen::VectorXd ard_alpha;

  /// "trainbr: ssE 3.1 -> 0.02 in 212 epochs, gamma 17.2 of 50, max_mu (...)" (normalized ssE;
  /// F is left out: trainbr's alpha/beta rule keeps it near n / 2 at the start and the end).
  std::string BriefReport() const;
};
void to_json(nlohmann::json& j, const TrainSummary& s);
void from_json(const nlohmann::json& j, TrainSummary& s);

struct TrainResult {
  Network network;  ///< final weights
  TrainSummary summary;
  /// A^-1 = (2 (beta J'J + alpha I))^-1 at the final weights, final alpha, beta (with
  /// TrainOptions::ard kept: diag(alpha_g(i)) in place of alpha I): the Laplace (Gauss-Newton)
  /// posterior covariance of w, N x N, flat order. Empty without regularization.
  Eigen::MatrixXd posterior_covariance;
  std::uint64_t init_seed = 0;  ///< seed of InitNguyenWidrow (0 if the caller initialized)
};

/// Trains `initial` with trainbr (or plain LM) on `data`. Throws InputError on inconsistent sizes,
/// non-finite data or bad options; a run that stops on mu or epochs is a Summary, not a throw.
TrainResult TrainBr(const TrainingData& data, const Network& initial, const TrainOptions& options,
                    const EpochCallback& callback = {});

/// MacKay's log evidence in MATLAB's alpha/beta convention (derived from MacKay 1992 eq. 4.9
/// with alpha_M = 2 alpha, beta_M = 2 beta, A = 2 H):
///   ln P(D | alpha, beta) = -F - 1/2 ln det H + (N/2) ln alpha + (n/2) ln beta - (n/2) ln pi
///                           + sum over hidden layers of ln(2^A_h S_h! / (S_h - A_h)!),
/// F = beta ssE + alpha ssX, H = beta J'J + alpha I. The last term counts the equivalent weight
/// vectors of a tansig layer of S neurons (MacKay, "A practical Bayesian framework for backprop
/// networks", 1992, section 6: 2^S S! when every neuron is distinct); it matters only when
/// comparing hidden sizes. A_h = active_units[h] (ActiveHiddenUnits; empty = all S_h): a neuron the
/// data leave at the prior (weights near 0) coincides with its sign-flipped and swapped images and
/// adds none. Without that correction a collapsed network (every weight near 0, gamma near 0)
/// of 8 neurons got ln(2^8 8!) = 16.1 more evidence than the same function without hidden
/// neurons (ln(2^8 8!) - ln(2^4 4!) = 10.2 more than with 4), and
/// the default chose such fits over fitted ones (docs/network.md, "Against its peers").
double LogEvidence(double sse, double ssx, double alpha, double beta, double log_det_h,
                   int parameter_count, int error_count, const std::vector<int>& layer_sizes,
                   const std::vector<int>& active_units = {});

/// A neuron counts as active (ActiveHiddenUnits) when the data determine at least this many
/// effective parameters among its bias, incoming and outgoing weights.
inline constexpr double kActiveUnitGamma = 0.5;

/// Per hidden layer, the neurons the data determine: neuron r of hidden layer h counts when
/// sum_i gamma_i >= kActiveUnitGamma over its bias, its incoming weights and its outgoing weights,
/// with gamma_i = 1 - alpha_i (H^-1)_ii (MacKay's well-determined parameters, H^-1 = 2
/// posterior_covariance). InputError unless the covariance is N x N and alpha_per_parameter has
/// N entries.
std::vector<int> ActiveHiddenUnits(const Network& net, const Eigen::MatrixXd& posterior_covariance,
                                   const Eigen::VectorXd& alpha_per_parameter);

/// LogEvidence with one alpha per weight group (TrainOptions::ard): the prior term becomes
/// sum_g (N_g / 2) ln alpha_g - alpha_g ssX_g, H = beta J'J + diag(alpha_g(i)); equal to
/// LogEvidence when all alpha_g are equal.
double LogEvidenceGroups(double sse, const Eigen::VectorXd& group_ssx,
                         const Eigen::VectorXd& group_alpha, const Eigen::VectorXd& group_size,
                         double beta, double log_det_h, int error_count,
                         const std::vector<int>& layer_sizes,
                         const std::vector<int>& active_units = {});

/// Largest alpha_g of TrainOptions::ard (normalized units; the group's weights are then
/// effectively zero).
inline constexpr double kArdAlphaMax = 1e12;

/// The ARD stage is kept when its log evidence exceeds trainbr's by more than this times
/// max(1, |trainbr's log evidence|): a stage that barely moved is not "kept" by rounding.
inline constexpr double kArdEvidenceMargin = 1e-6;

/// One training run of a restart series.
struct RestartRecord {
  std::uint64_t seed = 0;
  double log_evidence = 0;
  double sse = 0;
  double gamma = 0;
  int epochs = 0;
  TrainTermination termination = TrainTermination::kMaxEpochs;
};
void to_json(nlohmann::json& j, const RestartRecord& r);
void from_json(const nlohmann::json& j, RestartRecord& r);

struct RestartResult {
  TrainResult best;
  int best_index = 0;               ///< index into runs
  std::vector<RestartRecord> runs;  ///< in seed order
};

/// Trains `restarts` networks of `layer_sizes`, initialized by InitNguyenWidrow with seeds
/// seed, seed + 1, ..., seed + restarts - 1, and keeps the one with the HIGHEST log evidence
/// (lowest ssE under Regularization::kNone); ties keep the earlier seed. The callback receives
/// the restart index (0-based) with each epoch (serialized by a lock; epochs of different restarts
/// interleave). The restarts run on `threads` threads (core/parallel.h; <= 0: all cores); the
/// result is identical for any thread count (selection happens after all runs, in seed order).
RestartResult TrainBrRestarts(const TrainingData& data, const std::vector<int>& layer_sizes,
                              std::uint64_t seed, int restarts, const TrainOptions& options,
                              const std::function<void(int, const EpochInfo&)>& callback = {},
                              int threads = 0);

}  // namespace whirl::nn
