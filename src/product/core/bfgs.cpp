#include "core/bfgs.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl {
namespace {

// One trial point of the line search: step length a, phi(a) = f(x + a p), phi'(a) = g'p.
struct Trial {
  double a = 0, f = 0, d = 0;
  Eigen::VectorXd g;
  bool Finite() const { return std::isfinite(f) && std::isfinite(d); }
};

class LineSearch {
 public:
  LineSearch(const SmoothObjective& f, const Eigen::VectorXd& x, const Eigen::VectorXd& p,
             const Trial& start, const BfgsOptions& o, int* evaluations)
      : f_(f), x_(x), p_(p), start_(start), o_(o), evaluations_(evaluations) {}

  // Nocedal & Wright Algorithm 3.5; true with *out satisfying the strong Wolfe conditions.
  bool Run(double a_initial, Trial* out) {
    Trial prev = start_;
    double a = a_initial;
    for (int i = 0; i < o_.max_line_search_steps; ++i) {
      const Trial t = Evaluate(a);
      if (!t.Finite() || t.f > start_.f + o_.wolfe_c1 * a * start_.d || (i > 0 && t.f >= prev.f))
        return Zoom(prev, t, out);
      if (std::abs(t.d) <= -o_.wolfe_c2 * start_.d) return Accept(t, out);
      if (t.d >= 0) return Zoom(t, prev, out);
      prev = t;
      a *= 2.0;
    }
    return false;
  }

 private:
  Trial Evaluate(double a) {
    Trial t;
    t.a = a;
    t.g.resize(x_.size());
    t.f = f_(x_ + a * p_, &t.g);
    t.d = t.g.dot(p_);
    ++*evaluations_;
    return t;
  }

  static bool Accept(const Trial& t, Trial* out) {
    *out = t;
    return true;
  }

  // Minimizer of the cubic through (lo, hi) with their slopes (N&W eq. 3.59), kept inside the
  // middle 80 % of the bracket; bisection when the cubic has no usable minimizer.
  static double Interpolate(const Trial& lo, const Trial& hi) {
    const double left = std::min(lo.a, hi.a), right = std::max(lo.a, hi.a);
    const double mid = 0.5 * (lo.a + hi.a), margin = 0.1 * (right - left);
    if (!lo.Finite() || !hi.Finite()) return mid;
    const double d1 = lo.d + hi.d - 3.0 * (lo.f - hi.f) / (lo.a - hi.a);
    const double disc = d1 * d1 - lo.d * hi.d;
    if (disc < 0) return mid;
    const double d2 = (hi.a > lo.a ? 1.0 : -1.0) * std::sqrt(disc);
    const double a = hi.a - (hi.a - lo.a) * (hi.d + d2 - d1) / (hi.d - lo.d + 2.0 * d2);
    if (!std::isfinite(a) || a < left + margin || a > right - margin) return mid;
    return a;
  }

  // Nocedal & Wright Algorithm 3.6: lo satisfies sufficient decrease and has the lowest f so far.
  bool Zoom(Trial lo, Trial hi, Trial* out) {
    for (int i = 0; i < o_.max_line_search_steps; ++i) {
      const Trial t = Evaluate(Interpolate(lo, hi));
      if (!t.Finite() || t.f > start_.f + o_.wolfe_c1 * t.a * start_.d || t.f >= lo.f) {
        hi = t;
        continue;
      }
      if (std::abs(t.d) <= -o_.wolfe_c2 * start_.d) return Accept(t, out);
      if (t.d * (hi.a - lo.a) >= 0) hi = lo;
      lo = t;
    }
    // No Wolfe point: still take the best sufficient-decrease point, if any moved.
    if (lo.a > 0 && lo.f < start_.f) return Accept(lo, out);
    return false;
  }

  const SmoothObjective& f_;
  const Eigen::VectorXd& x_;
  const Eigen::VectorXd& p_;
  const Trial& start_;
  const BfgsOptions& o_;
  int* evaluations_;
};

void ValidateOptions(const BfgsOptions& o) {
  if (o.max_iterations < 0)
    throw InputError("bfgs: max_iterations " + std::to_string(o.max_iterations) + ": must be >= 0");
  if (o.max_line_search_steps < 1)
    throw InputError("bfgs: max_line_search_steps " + std::to_string(o.max_line_search_steps) +
                     ": must be >= 1");
  if (!(0 < o.wolfe_c1 && o.wolfe_c1 < o.wolfe_c2 && o.wolfe_c2 < 1))
    throw InputError("bfgs: wolfe_c1 " + MessageNumber(o.wolfe_c1) + ", wolfe_c2 " +
                     MessageNumber(o.wolfe_c2) + ": need 0 < c1 < c2 < 1");
}

// N&W eq. 6.17 (with eq. 6.20 before the first update); false when y's <= 0 (update skipped).
bool UpdateInverseHessian(const Eigen::VectorXd& s, const Eigen::VectorXd& y, bool first,
                          Eigen::MatrixXd* h) {
  const double ys = y.dot(s);
  if (!(ys > 0)) return false;
  if (first) *h = Eigen::MatrixXd::Identity(s.size(), s.size()) * (ys / y.squaredNorm());
  const double rho = 1.0 / ys;
  const Eigen::VectorXd hy = *h * y;
  // (I - rho s y') H (I - rho y s') + rho s s', expanded (H symmetric).
  *h += (rho * rho * y.dot(hy) + rho) * (s * s.transpose()) -
        rho * (hy * s.transpose() + s * hy.transpose());
  return true;
}

}  // namespace

std::string ToString(BfgsTermination t) {
  switch (t) {
    case BfgsTermination::kGradientTolerance:
      return "gradient_tolerance";
    case BfgsTermination::kFunctionTolerance:
      return "function_tolerance";
    case BfgsTermination::kMaxIterations:
      return "max_iterations";
    case BfgsTermination::kLineSearchFailed:
      return "line_search_failed";
    case BfgsTermination::kNonFiniteStart:
      return "non_finite_start";
  }
  return "unknown";
}

std::string BfgsSummary::BriefReport() const {
  return "bfgs: f " + MessageNumber(initial_cost) + " -> " + MessageNumber(final_cost) + " in " +
         std::to_string(iterations) + " iterations (" + std::to_string(evaluations) +
         " evaluations), " + ToString(termination) + " (" + message + ")";
}

BfgsSummary MinimizeBfgs(const SmoothObjective& f, Eigen::VectorXd* x, const BfgsOptions& options) {
  ValidateOptions(options);
  BfgsSummary s;
  Trial cur;
  cur.g.resize(x->size());
  cur.f = f(*x, &cur.g);
  s.evaluations = 1;
  s.initial_cost = s.final_cost = cur.f;
  if (!std::isfinite(cur.f) || !cur.g.allFinite()) {
    s.termination = BfgsTermination::kNonFiniteStart;
    s.message = "f(x0) = " + MessageNumber(cur.f) + " or its gradient is not finite";
    return s;
  }
  Eigen::MatrixXd h = Eigen::MatrixXd::Identity(x->size(), x->size());
  bool first = true;
  s.termination = BfgsTermination::kMaxIterations;
  s.message = std::to_string(options.max_iterations) + " iterations";
  for (; s.iterations < options.max_iterations; ++s.iterations) {
    const double gmax = cur.g.cwiseAbs().maxCoeff();
    if (gmax <= options.gradient_tolerance) {
      s.termination = BfgsTermination::kGradientTolerance;
      s.message =
          "max |g| " + MessageNumber(gmax) + " <= " + MessageNumber(options.gradient_tolerance);
      break;
    }
    Eigen::VectorXd p = -h * cur.g;
    if (!(p.dot(cur.g) < 0)) {
      h.setIdentity();
      p = -cur.g;
    }
    cur.d = p.dot(cur.g);
    cur.a = 0;  // the line search measures steps from here
    // First step: unit length in x (the unscaled H_0 = I step can be far off).
    const double a0 = first ? std::min(1.0, 1.0 / p.norm()) : 1.0;
    Trial next;
    LineSearch search(f, *x, p, cur, options, &s.evaluations);
    if (!search.Run(a0, &next)) {
      s.termination = BfgsTermination::kLineSearchFailed;
      s.message = "no step along the search direction met the Wolfe conditions (slope " +
                  MessageNumber(cur.d) + ")";
      break;
    }
    const Eigen::VectorXd step = next.a * p;
    *x += step;
    if (UpdateInverseHessian(step, next.g - cur.g, first, &h)) first = false;
    const double decrease = cur.f - next.f;
    cur = next;
    if (decrease <= options.function_tolerance * std::max(1.0, std::abs(cur.f))) {
      ++s.iterations;
      s.termination = BfgsTermination::kFunctionTolerance;
      s.message = "decrease " + MessageNumber(decrease) +
                  " <= " + MessageNumber(options.function_tolerance) + " * max(1, |f|)";
      break;
    }
  }
  s.final_cost = cur.f;
  s.gradient_max_norm = cur.g.cwiseAbs().maxCoeff();
  return s;
}

}  // namespace whirl
