#pragma once
// A general, reusable Levenberg-Marquardt least-squares solver (Eigen only).
//
//   minimise  cost(x) = 1/2 * sum_i r_i(x)^2      subject to  lower <= x <= upper (optional)
//
// Shape after ceres-solver include/ceres/tiny_solver.h (STYLE.md 1): LmOptions with defaults, one
// run function SolveLeastSquares, an LmSummary with initial/final cost, iterations, a termination
// reason and a message that carries the compared numbers.
//
// Algorithm (Madsen, Nielsen & Tingleff, "Methods for non-linear least squares problems", 2004,
// section 3.2; Nielsen's damping update as in tiny_solver):
//   g = J' r,  A = J'J,  D = diag(max(diag(A), kMinDiagonal))
//   step  h = -(A + mu D)^-1 g;  x_new = Project(x + h)  (Project clamps each entry into its box)
//   gain  rho = (cost(x) - cost(x_new)) / (L(0) - L(h_p)),  L(h) = cost + g'h + h'Ah/2, h_p = x_new
//   - x rho > 0: accept, mu *= max(1/3, 1 - (2 rho - 1)^3), nu = 2;   else mu *= nu, nu *= 2.
// Positivity (or any box) is kept by projection onto the bounds: set lower_bounds to a small
// positive number for parameters that must stay positive. Convergence with bounds is measured on
// the projected gradient ||Project(x - g) - x||_inf, which is zero at a constrained optimum.
#include <Eigen/Core>
#include <functional>
#include <string>

namespace whirl::fit {

/// Residuals r(x) (size m) and, when `jacobian` is not null, J_r_x (m x n, J(i,j) = d r_i / d x_j).
/// A functor that never fills the Jacobian must be passed with `analytic_jacobian = false`; the
/// solver then uses central finite differences.
using ResidualFunction = std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd* residuals,
                                            Eigen::MatrixXd* jacobian)>;

struct LmOptions {
  /// Maximum number of outer iterations (Jacobian evaluations). Reaching it is an outcome.
  int max_iterations = 200;
  /// Stop when the (projected) gradient ||Project(x - J'r) - x||_inf <= gradient_tolerance.
  double gradient_tolerance = 1e-12;
  /// Stop when an accepted step satisfies ||h||_2 <= parameter_tolerance * (||x||_2 +
  /// parameter_tolerance).
  double parameter_tolerance = 1e-10;
  /// Stop when an accepted step lowers the cost by less than cost_tolerance * cost (relative).
  double cost_tolerance = 1e-14;
  /// Initial damping mu relative to the largest diagonal entry of J'J (Madsen et al. tau, 1e-6..1).
  double initial_mu = 1e-4;
  /// Give up when mu grows beyond this (no step lowers the cost any more).
  double max_mu = 1e32;
  /// Central-difference step relative to |x_j| (absolute floor: the same value) when no analytic
  /// Jacobian is given: h_j = fd_relative_step * max(|x_j|, 1).
  double fd_relative_step = 1e-6;
  /// Optional box bounds (empty = unbounded; else size n, use +-infinity for a free side).
  Eigen::VectorXd lower_bounds;
  Eigen::VectorXd upper_bounds;
};

enum class LmTermination {
  kGradientTolerance,   ///< projected gradient small: converged
  kParameterTolerance,  ///< step small relative to x: converged
  kCostTolerance,       ///< relative cost decrease small: converged
  kZeroCost,            ///< cost exactly 0: converged
  kMaxIterations,       ///< iteration limit reached: not converged
  kMuTooLarge,          ///< damping exceeded max_mu without a decrease: stalled
  kNonFinite,           ///< residuals or Jacobian not finite at the start: failed
};

/// "gradient_tolerance", "parameter_tolerance", ... (used in JSON and messages).
std::string ToString(LmTermination t);

struct LmSummary {
  double initial_cost = 0;  ///< 1/2 ||r(x0)||^2
  double final_cost = 0;    ///< 1/2 ||r(x)||^2 at the returned x
  int iterations = 0;       ///< outer iterations performed (accepted and rejected steps)
  int accepted_steps = 0;
  double final_gradient_norm = 0;  ///< projected gradient, inf-norm
  double final_mu = 0;
  LmTermination termination = LmTermination::kMaxIterations;
  std::string
      message;  ///< the numbers compared for the termination, e.g. "gradient 3e-13 <= 1e-12"

  /// True for the four converged reasons.
  bool Converged() const;
  /// One line: "LM: cost 12.3 -> 0.0045 in 17 iterations, gradient_tolerance (gradient ...)".
  std::string BriefReport() const;
};

/// Minimises 1/2 ||r(x)||^2 from the start point in *x (projected onto the bounds first) and leaves
/// the best point found in *x. `num_residuals` is m. Bad options (non-positive tolerances, bounds
/// of the wrong size or lower > upper, m < 1) throw InputError; non-convergence is a Summary
/// outcome.
LmSummary SolveLeastSquares(const ResidualFunction& residual, int num_residuals,
                            bool analytic_jacobian, Eigen::VectorXd* x,
                            const LmOptions& options = {});

/// Central finite-difference Jacobian of `residual` at x with step fd_relative_step * max(|x_j|,1),
/// clamped so the stencil stays inside the bounds (one-sided at a bound). Used by the solver and
/// by tests that compare analytic Jacobians.
Eigen::MatrixXd FiniteDifferenceJacobian(const ResidualFunction& residual, int num_residuals,
                                         const Eigen::VectorXd& x, const LmOptions& options = {});

}  // namespace whirl::fit
