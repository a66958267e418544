#pragma once
// Unconstrained minimization of a smooth function of a few variables (up to a few dozen) by the
// BFGS quasi-Newton method with a strong-Wolfe line search (Nocedal & Wright, "Numerical
// Optimization", 2nd ed. 2006: Algorithm 6.1 with the initial scaling of eq. 6.20, the line search
// of Algorithms 3.5 and 3.6 with safeguarded cubic interpolation, section 3.5).
//
// Why a dense BFGS of our own and not a library: the Gaussian-process hyperparameters (gp/gp.h)
// have 7-8 variables, so the dense n x n inverse-Hessian approximation costs nothing and the
// memory saving of L-BFGS is moot. Debian packages LBFGSpp (liblbfgspp-dev, header-only, Eigen)
// and libLBFGS (liblbfgs-dev, C); both report a failed line search by throwing (LBFGSpp) or by an
// error code without the iterate bookkeeping we want, and either would be a new build dependency
// for about 150 lines of code. Here a run that does not converge is a Summary (STYLE.md 2).
//
// Iteration k, with x_k, f_k, g_k and H_k (approximate inverse Hessian, H_0 = I):
//   p_k = -H_k g_k (reset to -g_k if p_k'g_k >= 0),
//   x_k+1 = x_k + a_k p_k, a_k satisfying the strong Wolfe conditions
//     f(x_k + a p_k) <= f_k + c1 a g_k'p_k,  |g(x_k + a p_k)'p_k| <= c2 |g_k'p_k|,
//   s = x_k+1 - x_k, y = g_k+1 - g_k, rho = 1 / y's;
//   before the first update H_0 = (y's / y'y) I (eq. 6.20);
//   H_k+1 = (I - rho s y') H_k (I - rho y s') + rho s s'   (eq. 6.17; skipped when y's <= 0).
// A non-finite f or gradient at a trial point counts as "too far" in the line search.
#include <Eigen/Core>
#include <functional>
#include <string>

namespace whirl {

/// f(x); when `gradient` is non-null also writes df/dx into it (resized by the callee is not
/// needed: it has x.size() entries on entry).
using SmoothObjective = std::function<double(const Eigen::VectorXd& x, Eigen::VectorXd* gradient)>;

struct BfgsOptions {
  int max_iterations = 200;          ///< outer iterations (line searches)
  int max_line_search_steps = 30;    ///< function evaluations per line search
  double gradient_tolerance = 1e-6;  ///< stop when max_i |g_i| <= this (units of f per unit x)
  /// Stop when |f_k - f_k+1| <= function_tolerance * max(1, |f_k+1|) (relative decrease).
  double function_tolerance = 1e-10;
  double wolfe_c1 = 1e-4;  ///< sufficient-decrease constant c1 (Nocedal & Wright: 1e-4)
  double wolfe_c2 = 0.9;   ///< curvature constant c2 (quasi-Newton: 0.9)
};

enum class BfgsTermination {
  kGradientTolerance,  ///< max |g_i| <= gradient_tolerance
  kFunctionTolerance,  ///< relative decrease below function_tolerance
  kMaxIterations,      ///< max_iterations reached
  kLineSearchFailed,   ///< no step along p_k satisfied the Wolfe conditions (x is the best found)
  kNonFiniteStart,     ///< f or its gradient is not finite at the initial x
};
std::string ToString(BfgsTermination t);  ///< "gradient_tolerance", ...

struct BfgsSummary {
  double initial_cost = 0;       ///< f(x_0)
  double final_cost = 0;         ///< f at the returned x (the lowest value seen)
  double gradient_max_norm = 0;  ///< max |g_i| at the returned x
  int iterations = 0;
  int evaluations = 0;  ///< calls of the objective
  BfgsTermination termination = BfgsTermination::kMaxIterations;
  std::string message;  ///< the reason with the numbers it compared
  /// "bfgs: f 12.3 -> 4.56 in 31 iterations (45 evaluations), gradient_tolerance (...)".
  std::string BriefReport() const;
};

/// Minimizes f from *x; on return *x holds the best point found. Throws InputError only on
/// invalid options (max_iterations < 0, c1, c2 outside 0 < c1 < c2 < 1); a run that does not
/// converge is a Summary.
BfgsSummary MinimizeBfgs(const SmoothObjective& f, Eigen::VectorXd* x,
                         const BfgsOptions& options = {});

}  // namespace whirl
