#pragma once
// Gaussian-process regression of one output on a few inputs (Rasmussen & Williams, "Gaussian
// Processes for Machine Learning", MIT Press 2006; cited below as R&W with equation numbers).
//
// Model, in the standardized space (inputs z = (x - input_shift) / input_scale per input, target
// u = (y - target_shift) / target_scale, shift = mean and scale = sd of the training column, 1 for
// a constant column):
//   u(z) = h(z)' b + f(z) + eps,  f ~ GP(0, k),  eps ~ N(0, sigma_n^2),
//   h(z) = (1) (Mean::kConstant) or (1, z_1, ..., z_d) (Mean::kLinear),
//   b by generalized least squares at the current hyperparameters (profiled out):
//     K = K_f + sigma_n^2 I,  b = (H' K^-1 H)^-1 H' K^-1 u,  r = u - H b,  alpha = K^-1 r.
//   ARD kernels with length scales l_i (r^2 = sum_i (z_i - z'_i)^2 / l_i^2) and signal sd s_f:
//     Kernel::kSquaredExponential: k = s_f^2 exp(-r^2 / 2)                       (R&W eq. 5.1)
//     Kernel::kMatern52:           k = s_f^2 (1 + sqrt5 r + 5 r^2 / 3) exp(-sqrt5 r)  (eq. 4.17)
// Hyperparameters theta = (ln l_1..ln l_d, ln s_f, ln s_n), sigma_n^2 = s_n^2 + min_noise_variance,
// chosen by type-II maximum likelihood (R&W section 5.4.1): minimize
//   NLML(theta) = r' alpha / 2 + sum_i ln L_ii + (n / 2) ln 2 pi       (eq. 2.30; K = L L'),
// with the analytic gradient dNLML/dtheta_j = -tr((alpha alpha' - K^-1) dK/dtheta_j) / 2 (eq. 5.9;
// valid with b profiled out because dNLML/db = 0 at the GLS b), by BFGS (core/bfgs.h) from
// `restarts` fixed starting points; the lowest NLML wins.
//
// Prediction at z* (R&W eqs. 2.25-2.26 and, for the mean's uncertainty, eq. 2.42):
//   mean = h*' b + k*' alpha,
//   latent variance = k(z*, z*) - k*' K^-1 k* + R' (H' K^-1 H)^-1 R,  R = h* - H' K^-1 k*,
//   predictive variance = latent variance + noise_variance,
// all times target_scale (sd) or target_scale^2 (variance) in the units of y.
// noise_variance starts as sigma_n^2 and may be replaced by a calibrated level (family/).
//
// Closed-form leave-one-out (R&W eq. 5.12, with b re-estimated without row i: the projection
// P = K^-1 - K^-1 H (H' K^-1 H)^-1 H' K^-1 has P u = alpha): residual u_i - mean_-i = alpha_i /
// P_ii, predictive variance 1 / P_ii; exact for fixed hyperparameters.
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/bfgs.h"

namespace whirl::gp {

enum class Kernel { kSquaredExponential, kMatern52 };
enum class Mean { kConstant, kLinear };
std::string ToString(Kernel k);            ///< "squared_exponential", "matern52"
std::string ToString(Mean m);              ///< "constant", "linear"
Kernel ParseKernel(const std::string& s);  ///< inverse; InputError otherwise
Mean ParseMean(const std::string& s);      ///< inverse; InputError otherwise

/// core/bfgs.h defaults with function_tolerance 1e-5 and gradient_tolerance 1e-4 (tables below
/// GpOptions::single_start_rows), or 1e-4 and 1e-3 (larger tables).
inline BfgsOptions GpBfgsDefaults(bool large = false) {
  BfgsOptions b;
  b.function_tolerance = large ? 1e-4 : 1e-5;
  b.gradient_tolerance = large ? 1e-3 : 1e-4;
  return b;
}

struct GpOptions {
  Kernel kernel = Kernel::kMatern52;
  Mean mean = Mean::kConstant;
  /// true: one length scale for all (standardized) inputs, l_1 = ... = l_d = l (an isotropic
  /// kernel, R&W eq. 4.9 and 4.17 with a scalar l): the likelihood is maximized over
  /// (ln l, ln s_f, ln s_n), dNLML/d ln l = sum_i dNLML/d ln l_i; Gp::theta still holds d equal
  /// length scales, so predictions, leave-one-out and files are those of the ARD form.
  bool isotropic = false;
  /// Starting points of the likelihood maximization (1..kStartCount) for fits on fewer than
  /// single_start_rows rows (one start from there on), from a fixed list (no random numbers: the
  /// same table gives the same GP everywhere; the lowest objective wins): length scales sqrt(d),
  /// signal sd 1 and noise sd 0.1 in standardized target units; then length scales 2 sqrt(d),
  /// signal sd s and noise sd 0.1 s, s the sd that the mean's least-squares fit leaves of the
  /// standardized targets (small where a power-law mean fits well); then (0.5 sqrt(d), 1, 0.3),
  /// (0.25 sqrt(d), 1, 0.5). Why two below 70 rows: on the benchmark's tuning part each of the
  /// first two starts alone fell into local optima the other avoided (the first missed the bend
  /// of power laws bent in one input in refits of 16 rows, the second took noise for signal on
  /// exact power laws); from 70 rows on one start changed no median and halves the time
  /// (docs/workpiece-history.md).
  int restarts = 2;
  int single_start_rows = 70;
  /// A log-normal prior on every length scale (the hyperparameters maximize the likelihood times
  /// the prior: maximum a posteriori, R&W section 5.4.1's hierarchical view), the
  /// dimension-scaled prior of Hvarfner, Hellsten & Nardi ("Vanilla Bayesian optimization
  /// performs great in high dimensions", ICML 2024), ln l ~ N(sqrt(2) + ln(d) / 2, 3) for inputs
  /// on the unit cube, moved to standardized inputs (a uniform input's range is sqrt(12) sd):
  ///   ln l_i ~ N(LengthPriorMean(d), length_prior_sd^2),
  ///   LengthPriorMean(d) = sqrt(2) + ln(d) / 2 + ln(sqrt(12))   (3.46 for 5 inputs).
  /// It keeps a GP from short length scales (spurious bends) that a few rows cannot support.
  /// length_prior_sd = 0: no prior (maximum likelihood). Why the prior: on the benchmark's tuning
  /// part (scripts/bench_peers.sh --split tuning) it lowered the median test RMSE of the additive
  /// and Friedman tables by 5-15 % at 20 and 100 rows (docs/workpiece-history.md).
  double length_prior_sd = 1.7320508075688772;  // sqrt(3)
  /// Subset of data for large tables (R&W section 8.3.2): a GP on at most max_rows rows of the
  /// table, spread evenly by index (row floor(j n / m), j = 0..m-1), when it has more (0: every
  /// row); the standardization still uses every row, and Gp::rows names the rows kept. One
  /// likelihood evaluation costs O(rows^3) and the leave-one-out O(rows^3): 512 rows keep a fit
  /// of 2,000 rows within the time of R brnn's (docs/workpiece-model.md, "Speed").
  int max_rows = 512;
  /// Hyperparameters from at most this many of the GP's rows (spread as above), the GP itself on
  /// all of them (0: all rows). 128: tables of up to 128 rows are fitted in full, and 2,000
  /// rows in about 0.5 s (below R brnn's 1 s). (20 rows per hyperparameter instead, 60 rows for
  /// the isotropic kernel at 100 rows, made Friedman's second output at 100 rows 13 % worse on
  /// the benchmark's tuning part.)
  int hyperparameter_rows = 128;
  /// Floor added to s_n^2, standardized target units (keeps K well conditioned when the data
  /// are interpolated; 1e-6 = noise sd of 0.1 % of the target's sd).
  double min_noise_variance = 1e-6;
  /// The optimizer's options below single_start_rows rows (bfgs) and from there on
  /// (bfgs_large). NLML is in nats, so a relative decrease of 1e-5 (about 2e-4 nats at 20 rows)
  /// and max |dNLML/dtheta| <= 1e-4 are far below what changes a prediction (an earlier default,
  /// 20-row tables: the same choices and medians within 0.5 % as with 1e-7, and 20-25 % less
  /// CPU). From 70 rows 1e-4 and 1e-3 changed no median of the benchmark's tuning part at 100
  /// rows by more than 0.5 % and save 15 % of the fit time; at 20 rows they moved single tables'
  /// choices (docs/workpiece-history.md).
  BfgsOptions bfgs = GpBfgsDefaults();
  BfgsOptions bfgs_large = GpBfgsDefaults(true);
  void Validate() const;  ///< InputError naming the option, its value and the rule
};
inline constexpr int kStartCount = 4;

/// The mean of GpOptions' length-scale prior for d inputs (standardized, natural log).
double LengthPriorMean(int d);

/// Number of mean coefficients m for d inputs (1, or 1 + d).
int MeanSize(Mean mean, int inputs);

/// NLML(theta) of the header comment for standardized inputs z (d x n, one sample per column) and
/// targets u (n); `gradient` (size d + 2) if non-null. +infinity when K is not positive definite.
double NegLogMarginalLikelihood(Kernel kernel, Mean mean, const Eigen::MatrixXd& z,
                                const Eigen::VectorXd& u, const Eigen::VectorXd& theta,
                                double min_noise_variance, Eigen::VectorXd* gradient);

/// A fitted GP for one output (see the header comment for every symbol).
struct Gp {
  Kernel kernel = Kernel::kMatern52;
  Mean mean = Mean::kConstant;
  Eigen::VectorXd input_shift, input_scale;   ///< per input, units of x
  double target_shift = 0, target_scale = 1;  ///< units of y
  Eigen::VectorXd theta;  ///< (ln l_1..ln l_d, ln s_f, ln s_n), standardized space
  double min_noise_variance = 1e-6;
  double noise_variance = 0;  ///< of predictions, standardized target units
  Eigen::MatrixXd z;          ///< d x n standardized training inputs
  Eigen::VectorXd u;          ///< n standardized training targets
  /// The rows of the training table the GP keeps (GpOptions::max_rows); empty: all rows, in order.
  /// Set by FitGp, not stored in files.
  std::vector<int> rows;
  // Derived by Factorize() from the fields above (not stored in files). The factors start as
  // factorizations of an empty matrix: Eigen's default LLT leaves its status unset, and copying a
  // Gp before Factorize() (FitGp does) would read it (UBSan: invalid ComputationInfo).
  Eigen::LLT<Eigen::MatrixXd> chol{Eigen::MatrixXd()};    ///< K = L L'
  Eigen::MatrixXd k_inv_h;                                ///< K^-1 H, n x m
  Eigen::LLT<Eigen::MatrixXd> a_chol{Eigen::MatrixXd()};  ///< H' K^-1 H = L_A L_A'
  Eigen::VectorXd b;                   ///< GLS mean coefficients
  Eigen::VectorXd alpha;               ///< K^-1 (u - H b)

  int InputCount() const { return static_cast<int>(z.rows()); }
  double SigmaN2() const;  ///< exp(2 theta_noise) + min_noise_variance (the fitted noise)
  /// Recomputes the derived fields; InputError if K or H' K^-1 H is not positive definite.
  void Factorize();
};

struct GpSummary {
  double nlml = 0;                  ///< NLML of the chosen start
  std::vector<double> start_nlml;   ///< NLML reached from each start, in start order
  BfgsSummary optimizer;            ///< of the chosen start
  std::string BriefReport() const;  ///< "gp matern52/constant: nlml 12.3 (starts 12.3, 14.1)"
};

/// Fits a GP to x (d x n, one sample per column, original units) and y (n). InputError if
/// sizes disagree, values are not finite, or n <= m + 1 (too few rows for the mean).
Gp FitGp(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const GpOptions& options,
         GpSummary* summary = nullptr);
/// Same, optimizing from `theta_start` only (warm start, e.g. a fold from the full fit; with
/// GpOptions::isotropic, from the mean of its log length scales).
Gp FitGpFrom(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const GpOptions& options,
             const Eigen::VectorXd& theta_start, GpSummary* summary = nullptr);

/// Predictions at x (d x q, original units): mean and variances in units of y (squared).
struct GpPrediction {
  Eigen::VectorXd mean;
  Eigen::VectorXd latent_variance;  ///< of the function (mean coefficients included)
  double noise_variance = 0;        ///< Gp::noise_variance in units of y squared
  Eigen::VectorXd Stddev() const;   ///< sqrt(latent + noise)
};
GpPrediction PredictGp(const Gp& gp, const Eigen::MatrixXd& x);
/// The latent posterior covariance of the function at x (d x q, original units), q x q in units
/// of y squared, mean coefficients included (R&W eq. 2.41): its diagonal is
/// PredictGp(gp, x).latent_variance. Used to ask what a new row would change (design/design.h).
Eigen::MatrixXd PosteriorCovariance(const Gp& gp, const Eigen::MatrixXd& x);

/// Closed-form leave-one-out of the training rows (header comment), units of y.
struct LeaveOneOut {
  Eigen::VectorXd residual;         ///< y_i - mean_-i
  Eigen::VectorXd latent_variance;  ///< predictive variance 1 / P_ii minus the fitted noise
};
LeaveOneOut LeaveOneOutGp(const Gp& gp);

/// Effective degrees of freedom of the fit at the training rows (Hastie, Tibshirani & Friedman,
/// "The Elements of Statistical Learning", eq. 7.32; R&W section 2.6): tr(S) of the smoother that
/// maps the targets to the fitted means at the training rows, u_hat = S u = u - sigma_n^2 P u
/// (P of the leave-one-out comment, sigma_n^2 the fitted noise), so df = n - sigma_n^2 tr(P);
/// between the mean's coefficient count m (the kernel adds nothing) and n (interpolation).
double EffectiveDegreesOfFreedom(const Gp& gp);

/// -NLML at the fitted hyperparameters (header comment, R&W eq. 2.30: the mean coefficients
/// profiled by GLS, no length-scale prior), from the stored factors: the log density of the
/// standardized targets u of the GP's rows. As a density of y in its units subtract
/// u.size() ln target_scale (family/family.h: GpLogEvidence).
double LogMarginalLikelihood(const Gp& gp);

/// JSON of the fields above the "Derived" line; from_json validates sizes and finiteness
/// (InputError naming the key) and calls Factorize().
void to_json(nlohmann::json& j, const Gp& gp);
void from_json(const nlohmann::json& j, Gp& gp);

}  // namespace whirl::gp
