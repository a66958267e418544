#pragma once
// Least squares for the drift models: Miao et al.'s multiple linear regression
//   error = b0 + sum_j b_j x_j  (x_j = a temperature rise [K] or a lagged copy of it)
// solved with Eigen (column-pivoting QR of the design matrix [1 X]), with the classical
// statistics of ordinary least squares (any regression text, e.g. Montgomery, Peck & Vining,
// "Introduction to Linear Regression Analysis", chapters 3 and 9):
//   residual std  s = sqrt(RSS / (n - p - 1))                    [um]
//   covariance    Cov(b) = s^2 (X1' X1)^-1, X1 = [1 X]           [um^2 / K^2 ...]
//   standard error of b_j = sqrt(Cov_jj)
//   R^2 = 1 - RSS / TSS  (TSS about the mean; 1 when TSS = 0 and RSS = 0)
//   VIF_j = 1 / (1 - R_j^2), R_j^2 of regressing x_j on the other regressors (with intercept);
//           1 for a single regressor, +inf for an exactly collinear one.
// The posterior of b under a flat prior and Gaussian noise is N(b, Cov(b)), which the on-line
// recalibration (drift/monitor.h) uses as its prior; xtx_inverse is kept for it unscaled.
#include <Eigen/Core>
#include <limits>
#include <string>
#include <vector>

namespace whirl::drift {

struct LinearFit {
  Eigen::VectorXd coefficients;     ///< b0 (intercept, um), then one per regressor
  Eigen::VectorXd standard_errors;  ///< sqrt(diag Cov), same order
  Eigen::MatrixXd covariance;       ///< s^2 (X1'X1)^-1, (p + 1) x (p + 1)
  Eigen::MatrixXd xtx_inverse;      ///< (X1'X1)^-1
  double residual_std_um = 0;       ///< s
  double r_squared = 0;
  int samples = 0;             ///< n
  int degrees_of_freedom = 0;  ///< n - p - 1
  Eigen::VectorXd vif;         ///< per regressor
};

/// OLS of y (n) on the columns of x (n x p) with an intercept. InputError if n <= p + 1, a value
/// is not finite or [1 X] is rank deficient (names the rank: collinear regressors).
LinearFit FitLinear(const Eigen::MatrixXd& x, const Eigen::VectorXd& y);

/// FitLinear on rows that arrive one at a time and are not kept (the final fit on every row of a
/// long log, drift/stream.h FitFiles): the R factor of the QR decomposition of [1 X y] is updated
/// every 4096 rows (Householder QR of the previous R stacked on the new rows), so memory is
/// (p + 2)^2 whatever the row count, and the accuracy is the QR's, not the normal equations'.
/// Fit() gives FitLinear's statistics: the coefficients by the same rank-checked column-pivoting
/// QR (of R's first p + 1 columns, which have the norms of [1 X]), RSS as the squared residual of
/// R's last column on them, TSS as that column's squared norm below the intercept's row, and the
/// VIF from the block R_22 below and right of the intercept (R_22' R_22 = X_c' X_c, X centred).
/// Equal to FitLinear on the same rows up to rounding; the same InputErrors.
class StreamingLeastSquares {
 public:
  explicit StreamingLeastSquares(int regressors);
  void Add(const Eigen::Ref<const Eigen::VectorXd>& x, double y);  ///< one row
  LinearFit Fit();
  long long samples() const { return n_; }

 private:
  void Flush();
  int p_;
  Eigen::MatrixXd r_, block_;
  int filled_ = 0;
  long long n_ = 0;
  bool have_r_ = false, finite_ = true;
};

/// The minimum-norm least-squares coefficients (b0 first) of y on [1 x], also for a rank-deficient
/// [1 x] (complete orthogonal decomposition of the unit-norm-scaled columns). For
/// cross-validation folds, where one block may leave two regressors collinear; never throws on
/// rank. FitLinear is the fit a model is built from.
Eigen::VectorXd LeastSquaresCoefficients(const Eigen::MatrixXd& x, const Eigen::VectorXd& y);

/// b0 + x b for every row of x.
Eigen::VectorXd EvaluateLinear(const Eigen::VectorXd& coefficients, const Eigen::MatrixXd& x);

/// Variance inflation factors of the columns of x (see the header comment).
Eigen::VectorXd VarianceInflation(const Eigen::MatrixXd& x);

/// First-order lag of a series sampled at times t [min], exact for a piecewise-constant input
/// (zero-order hold), the recursion a control runs every cycle:
///   y_0 = x_0,  y_k = y_{k-1} + a_k (x_k - y_{k-1}),  a_k = 1 - exp(-(t_k - t_{k-1}) / tau).
/// tau in the unit of t (> 0).
Eigen::VectorXd FirstOrderLag(const Eigen::VectorXd& x, const std::vector<double>& t, double tau);

/// A first-order warm-up in time since the start of each run, the sensor-free baseline:
///   e(t) = b0 + sum_j A_j (1 - exp(-(t - t0) / tau_j)),  j = 1..terms (1 or 2),
/// t0 the run's first sample (the step response of a first-order lag, FirstOrderLag with L_0 = 0),
/// optionally beside fixed regressors (e.g. sensor rises: e = b0 + c' x + sum_j A_j (...)).
/// A warm-up that cannot run away (issue 38): every tau_j lies between 2 sample intervals (what
/// the sampling resolves) and the trained time range T (the longest run's t - t0; a slower
/// warm-up is not identified by the data), and the gains share one sign, so the warm-up part is
/// monotone, its plateau is sum_j A_j and no two large opposite gains cancel. Beyond T the terms go
/// on towards 1: the prediction approaches the plateau b0 + sum_j A_j and never passes it.
struct WarmUpFit {
  std::vector<double> time_constants;  ///< tau_j ascending [unit of t]; 2 asked may give 1
  Eigen::VectorXd coefficients;        ///< b0 [um], the fixed columns' c, then A_j [um]
  double rmse_um = 0;                  ///< training RMSE
  double span = 0;                     ///< T, the longest run's t - t0 [unit of t]
  /// false when the best tau is the upper bound T: the warm-up is slower than the training
  /// shows and its plateau is a bound, not a measured level; `note` says so.
  bool identified = true;
  std::string note;  ///< also when two terms collapsed to one (gains of opposite sign)
};

/// The longest elapsed-time constant a warm-up may take, as a multiple of the trained time range.
inline constexpr double kMaxWarmUpTauPerSpan = 1.0;

/// Variable projection (Golub & Pereyra, "The differentiation of pseudo-inverses and nonlinear
/// least squares problems whose variables separate"): for fixed time constants the gains are
/// linear (least squares on the stacked runs, each run's time since its own start), so only tau is
/// searched: a log grid of 41 points from 2 sample intervals (the median step) to
/// kMaxWarmUpTauPerSpan x T, then a golden-section refinement of log tau between the best point's
/// neighbours (coordinate-wise for two terms, which need tau_2 >= 3 tau_1). Two gains of opposite
/// sign are not allowed: the sign-constrained least squares is then the better of each term
/// alone, and a two-term fit whose best is one term returns one term (with a note).
/// Deterministic, never diverges.
/// `times`: time since each run's start, t - t0 [min or samples], and `errors` [um], per run;
/// `fixed`: extra regressors, one row per sample of the runs in order (0 columns: none).
/// InputError when no run has 3 samples.
/// `sampling_step` (optional): the sampling step of the logs the runs were thinned from
/// (drift/stream.h FitFiles), which then sets the shortest tau instead of the runs' median step.
/// Each candidate's least squares is computed on the time-constant columns with the intercept and
/// the fixed columns projected out (Frisch-Waugh-Lovell), the span of those factored once: the
/// same fit as a QR of the whole design up to rounding, in O(rows) per time constant tried.
WarmUpFit FitWarmUp(const std::vector<std::vector<double>>& times,
                    const std::vector<Eigen::VectorXd>& errors, int terms,
                    const Eigen::MatrixXd& fixed = Eigen::MatrixXd(),
                    double sampling_step = std::numeric_limits<double>::quiet_NaN());

}  // namespace whirl::drift
