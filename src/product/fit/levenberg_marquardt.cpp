#include "fit/levenberg_marquardt.h"

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::fit {
namespace {

// Floor for the Marquardt scaling diag(J'J) so a parameter the residuals ignore still gets damped.
constexpr double kMinDiagonal = 1e-12;

bool HasBounds(const LmOptions& o) {
  return o.lower_bounds.size() > 0 || o.upper_bounds.size() > 0;
}

double Lower(const LmOptions& o, Eigen::Index j) {
  return o.lower_bounds.size() > 0 ? o.lower_bounds[j] : -std::numeric_limits<double>::infinity();
}
double Upper(const LmOptions& o, Eigen::Index j) {
  return o.upper_bounds.size() > 0 ? o.upper_bounds[j] : std::numeric_limits<double>::infinity();
}

Eigen::VectorXd Project(const LmOptions& o, Eigen::VectorXd x) {
  if (!HasBounds(o)) return x;
  for (Eigen::Index j = 0; j < x.size(); ++j) x[j] = std::clamp(x[j], Lower(o, j), Upper(o, j));
  return x;
}

void ValidateOptions(const LmOptions& o, Eigen::Index n, int m) {
  auto positive = [](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v))
      throw InputError(std::string("LM option ") + name + " = " + MessageNumber(v) +
                       ": must be a positive finite number");
  };
  if (o.max_iterations < 0)
    throw InputError("LM option max_iterations = " + std::to_string(o.max_iterations) +
                     ": must be >= 0");
  positive(o.parameter_tolerance, "parameter_tolerance");
  positive(o.initial_mu, "initial_mu");
  positive(o.max_mu, "max_mu");
  positive(o.fd_relative_step, "fd_relative_step");
  if (!(o.gradient_tolerance >= 0))
    throw InputError("LM option gradient_tolerance = " + MessageNumber(o.gradient_tolerance) +
                     ": must be >= 0");
  if (!(o.cost_tolerance >= 0))
    throw InputError("LM option cost_tolerance = " + MessageNumber(o.cost_tolerance) +
                     ": must be >= 0");
  if (m < 1) throw InputError("LM: num_residuals = " + std::to_string(m) + ": must be >= 1");
  if (n < 1) throw InputError("LM: no parameters: x must have at least one entry");
  for (const auto* b : {&o.lower_bounds, &o.upper_bounds})
    if (b->size() != 0 && b->size() != n)
      throw InputError("LM: bounds have " + std::to_string(b->size()) + " entries for " +
                       std::to_string(n) + " parameters");
  if (HasBounds(o))
    for (Eigen::Index j = 0; j < n; ++j)
      if (!(Lower(o, j) <= Upper(o, j)))
        throw InputError("LM: lower bound " + MessageNumber(Lower(o, j)) + " > upper bound " +
                         MessageNumber(Upper(o, j)) + " for parameter " + std::to_string(j));
}

double ProjectedGradientNorm(const LmOptions& o, const Eigen::VectorXd& x,
                             const Eigen::VectorXd& g) {
  return (Project(o, x - g) - x).lpNorm<Eigen::Infinity>();
}

}  // namespace

std::string ToString(LmTermination t) {
  switch (t) {
    case LmTermination::kGradientTolerance:
      return "gradient_tolerance";
    case LmTermination::kParameterTolerance:
      return "parameter_tolerance";
    case LmTermination::kCostTolerance:
      return "cost_tolerance";
    case LmTermination::kZeroCost:
      return "zero_cost";
    case LmTermination::kMaxIterations:
      return "max_iterations";
    case LmTermination::kMuTooLarge:
      return "mu_too_large";
    case LmTermination::kNonFinite:
      return "non_finite";
  }
  return "unknown";
}

bool LmSummary::Converged() const {
  return termination == LmTermination::kGradientTolerance ||
         termination == LmTermination::kParameterTolerance ||
         termination == LmTermination::kCostTolerance || termination == LmTermination::kZeroCost;
}

std::string LmSummary::BriefReport() const {
  return "LM: cost " + MessageNumber(initial_cost) + " -> " + MessageNumber(final_cost) + " in " +
         std::to_string(iterations) + " iterations (" + std::to_string(accepted_steps) +
         " accepted), " + ToString(termination) + " (" + message + ")";
}

Eigen::MatrixXd FiniteDifferenceJacobian(const ResidualFunction& residual, int num_residuals,
                                         const Eigen::VectorXd& x, const LmOptions& options) {
  const Eigen::Index n = x.size();
  Eigen::MatrixXd jac(num_residuals, n);
  Eigen::VectorXd r_plus(num_residuals), r_minus(num_residuals);
  for (Eigen::Index j = 0; j < n; ++j) {
    const double h = options.fd_relative_step * std::max(std::abs(x[j]), 1.0);
    // Keep the stencil inside the box: one-sided differences at a bound.
    double up = h, down = h;
    if (HasBounds(options)) {
      up = std::min(h, Upper(options, j) - x[j]);
      down = std::min(h, x[j] - Lower(options, j));
      if (up <= 0 && down <= 0) up = down = h;  // degenerate box: ignore it for the stencil
      if (up <= 0) up = 0;
      if (down <= 0) down = 0;
    }
    Eigen::VectorXd xp = x, xm = x;
    xp[j] += up;
    xm[j] -= down;
    residual(xp, &r_plus, nullptr);
    residual(xm, &r_minus, nullptr);
    jac.col(j) = (r_plus - r_minus) / (up + down);
  }
  return jac;
}

namespace {

// The residual function with its Jacobian: analytic or by finite differences (at the point
// evaluated, inside the box), the residual count checked.
struct LmEvaluator {
  const ResidualFunction& residual;
  int num_residuals;
  bool analytic_jacobian;
  const LmOptions& options;

  void operator()(const Eigen::VectorXd& at, Eigen::VectorXd* res, Eigen::MatrixXd* j) const {
    res->resize(num_residuals);
    if (j != nullptr && analytic_jacobian) {
      j->resize(num_residuals, at.size());
      residual(at, res, j);
    } else {
      residual(at, res, nullptr);
      if (j != nullptr) *j = FiniteDifferenceJacobian(residual, num_residuals, at, options);
    }
    if (res->size() != num_residuals)
      throw InputError("LM: residual function returned " + std::to_string(res->size()) +
                       " residuals, expected " + std::to_string(num_residuals));
  }
};

// The stopping tests at the current point before a step: zero cost, then the projected gradient.
bool StopAtPoint(double cost, double grad_norm, const LmOptions& options, LmSummary* summary) {
  if (cost == 0) {
    summary->termination = LmTermination::kZeroCost;
    summary->message = "cost is exactly 0";
    return true;
  }
  if (grad_norm <= options.gradient_tolerance) {
    summary->termination = LmTermination::kGradientTolerance;
    summary->message = "projected gradient " + MessageNumber(grad_norm) +
                       " <= gradient_tolerance " + MessageNumber(options.gradient_tolerance);
    return true;
  }
  return false;
}

// The Marquardt step (J'J + mu diag(J'J)) step = -g (the diagonal floored at kMinDiagonal), its
// end projected on the box.
Eigen::VectorXd DampedStepEnd(const Eigen::MatrixXd& jtj, const Eigen::VectorXd& g, double mu,
                              const Eigen::VectorXd& x, const LmOptions& options) {
  Eigen::VectorXd diag = jtj.diagonal().cwiseMax(kMinDiagonal);
  Eigen::MatrixXd a = jtj;
  a.diagonal() += mu * diag;
  const Eigen::VectorXd step = a.ldlt().solve(-g);
  return Project(options, x + step);
}

// The parameter test on the projected step h from x.
bool StepTooSmall(const Eigen::VectorXd& h, const Eigen::VectorXd& x, const LmOptions& options,
                  LmSummary* summary) {
  const double step_norm = h.norm();
  if (step_norm > options.parameter_tolerance * (x.norm() + options.parameter_tolerance))
    return false;
  summary->termination = LmTermination::kParameterTolerance;
  summary->message = "step " + MessageNumber(step_norm) + " <= parameter_tolerance " +
                     MessageNumber(options.parameter_tolerance) + " * (|x| " +
                     MessageNumber(x.norm()) + " + tol)";
  return true;
}

// Gain ratio of the step h: the actual cost decrease (r the residuals before, r_new after) over
// the decrease the linear model predicts (g = J'r, jtj = J'J); -1 when the new cost is not finite
// or the model predicts no decrease. `decrease` receives the actual decrease.
double GainRatio(const Eigen::VectorXd& r, const Eigen::VectorXd& r_new, double cost_new,
                 const Eigen::VectorXd& g, const Eigen::MatrixXd& jtj, const Eigen::VectorXd& h,
                 double* decrease) {
  // cost - cost_new as 1/2 (r - r_new).(r + r_new): no cancellation near the optimum, where the
  // plain difference of two nearly equal costs is rounding noise.
  *decrease = 0.5 * (r - r_new).dot(r + r_new);
  const double model_decrease = -(g.dot(h) + 0.5 * h.dot(jtj * h));
  return (std::isfinite(cost_new) && model_decrease > 0) ? *decrease / model_decrease : -1.0;
}

// The cost test after an accepted step that decreased the cost by `decrease` to `cost`.
bool CostStalled(double decrease, double cost, const LmOptions& options, LmSummary* summary) {
  if (!(decrease <= options.cost_tolerance * (cost + decrease))) return false;
  summary->termination = LmTermination::kCostTolerance;
  summary->message = "relative cost decrease " + MessageNumber(decrease / (cost + decrease)) +
                     " <= cost_tolerance " + MessageNumber(options.cost_tolerance);
  return true;
}

// The damping test after a rejected step raised mu.
bool DampingTooLarge(double mu, double cost, const LmOptions& options, LmSummary* summary) {
  if (mu <= options.max_mu) return false;
  summary->termination = LmTermination::kMuTooLarge;
  summary->message = "damping mu " + MessageNumber(mu) + " > max_mu " +
                     MessageNumber(options.max_mu) + " without a cost decrease (cost " +
                     MessageNumber(cost) + ")";
  return true;
}

}  // namespace

LmSummary SolveLeastSquares(const ResidualFunction& residual, int num_residuals,
                            bool analytic_jacobian, Eigen::VectorXd* x_ptr,
                            const LmOptions& options) {
  if (x_ptr == nullptr) throw InputError("LM: x must not be null");
  Eigen::VectorXd& x = *x_ptr;
  const Eigen::Index n = x.size();
  ValidateOptions(options, n, num_residuals);
  x = Project(options, x);

  LmSummary summary;
  Eigen::VectorXd r(num_residuals);
  Eigen::MatrixXd jac(num_residuals, n);
  const LmEvaluator evaluate{residual, num_residuals, analytic_jacobian, options};
  evaluate(x, &r, &jac);
  double cost = 0.5 * r.squaredNorm();
  summary.initial_cost = summary.final_cost = cost;
  if (!std::isfinite(cost) || !jac.allFinite()) {
    summary.termination = LmTermination::kNonFinite;
    summary.message =
        "residuals or Jacobian not finite at the start point (cost " + MessageNumber(cost) + ")";
    return summary;
  }

  Eigen::MatrixXd jtj = jac.transpose() * jac;
  Eigen::VectorXd g = jac.transpose() * r;
  double mu = options.initial_mu * std::max(jtj.diagonal().maxCoeff(), kMinDiagonal);
  double nu = 2.0;
  Eigen::VectorXd r_new(num_residuals);

  summary.termination = LmTermination::kMaxIterations;
  summary.message = "reached max_iterations " + std::to_string(options.max_iterations);
  for (int iter = 0;; ++iter) {
    summary.final_gradient_norm = ProjectedGradientNorm(options, x, g);
    if (StopAtPoint(cost, summary.final_gradient_norm, options, &summary)) break;
    if (iter >= options.max_iterations) break;
    summary.iterations = iter + 1;
    const Eigen::VectorXd x_new = DampedStepEnd(jtj, g, mu, x, options);
    const Eigen::VectorXd h = x_new - x;
    if (StepTooSmall(h, x, options, &summary)) break;
    // The residual function is evaluated once here; the Jacobian only after acceptance.
    r_new.resize(num_residuals);
    residual(x_new, &r_new, nullptr);
    const double cost_new = 0.5 * r_new.squaredNorm();
    double decrease = 0;
    const double rho = GainRatio(r, r_new, cost_new, g, jtj, h, &decrease);
    if (rho > 0 && std::isfinite(cost_new)) {
      x = x_new;
      evaluate(x, &r, &jac);
      cost = cost_new;
      jtj = jac.transpose() * jac;
      g = jac.transpose() * r;
      ++summary.accepted_steps;
      mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      if (CostStalled(decrease, cost, options, &summary)) {
        summary.final_gradient_norm = ProjectedGradientNorm(options, x, g);
        break;
      }
    } else {
      mu *= nu;
      nu *= 2.0;
      if (DampingTooLarge(mu, cost, options, &summary)) break;
    }
  }
  summary.final_cost = cost;
  summary.final_mu = mu;
  return summary;
}

}  // namespace whirl::fit
