#pragma once
// Ordinary least squares of one output on the inputs with an intercept, with its closed-form
// leave-one-out (e.g. Hastie, Tibshirani & Friedman, "The Elements of Statistical Learning",
// 2nd ed. 2009, section 7.10, and Cook & Weisberg, "Residuals and Influence in Regression",
// 1982). On log inputs and a log output (family/transform.h) it is a power law
//   y = exp(c_0) prod_i x_i^c_i,
// the physics-shaped baseline the other families must beat.
//
// Design matrix A (n x (1 + d)): rows (1, z_i'), z = (x - input_shift) / input_scale (mean and
// population sd of the training column; 1 for a constant column). c = argmin ||y - A c||^2 by a
// column-pivoted QR; fitted noise s^2 = RSS / (n - 1 - d).
//   prediction at z*: mean a*' c, latent variance s^2 a*' (A'A)^-1 a*, a* = (1, z*');
//   leave-one-out (hat matrix H = A (A'A)^-1 A', h_i = H_ii; Sherman-Morrison):
//     residual y_i - mean_-i = e_i / (1 - h_i),  latent variance s^2 h_i / (1 - h_i),
//   with the full-data s^2 (exact for the mean; the variance uses s^2 of all rows).
#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace whirl::family {

struct LinearModel {
  Eigen::VectorXd input_shift, input_scale;  ///< per input, units of x
  Eigen::VectorXd coef;                      ///< c, 1 + d (intercept first), units of y
  Eigen::MatrixXd ata_inv;                   ///< (A'A)^-1, (1 + d) x (1 + d)
  double fitted_noise_variance = 0;          ///< s^2, units of y squared
  double noise_variance = 0;                 ///< of predictions (s^2 or a calibrated level)
};

/// InputError if sizes disagree, values are not finite or n <= d + 2 (no residual degree of
/// freedom left for s^2 after the leave-one-out).
LinearModel FitLinear(const Eigen::MatrixXd& x, const Eigen::VectorXd& y);

struct LinearPrediction {
  Eigen::VectorXd mean;             ///< units of y
  Eigen::VectorXd latent_variance;  ///< s^2 a*' (A'A)^-1 a*
};
LinearPrediction PredictLinear(const LinearModel& m, const Eigen::MatrixXd& x);
/// The latent covariance of the fit at x (d x q): s^2 A* (A'A)^-1 A*', q x q, units of y squared;
/// its diagonal is PredictLinear's latent_variance.
Eigen::MatrixXd LatentCovariance(const LinearModel& m, const Eigen::MatrixXd& x);

/// Closed-form leave-one-out of the training rows (header comment), units of y.
struct LinearLeaveOneOut {
  Eigen::VectorXd residual, latent_variance;
};
LinearLeaveOneOut LeaveOneOutLinear(const LinearModel& m, const Eigen::MatrixXd& x,
                                    const Eigen::VectorXd& y);

void to_json(nlohmann::json& j, const LinearModel& m);
/// InputError naming the key unless sizes agree and values are finite.
void from_json(const nlohmann::json& j, LinearModel& m);

}  // namespace whirl::family
