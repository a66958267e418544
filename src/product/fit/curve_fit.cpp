#include "fit/curve_fit.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "core/numbers.h"
#include "core/stats.h"

namespace whirl::fit {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void CheckCurve(const ElongationCurve& curve) {
  if (curve.time_s.size() != curve.elongation_um.size())
    throw InputError("curve: " + std::to_string(curve.time_s.size()) + " times but " +
                     std::to_string(curve.elongation_um.size()) + " elongation values");
  if (curve.size() < 3)
    throw InputError("curve: " + std::to_string(curve.size()) + " samples: a fit needs at least 3");
  for (std::size_t i = 0; i < curve.size(); ++i) {
    if (!std::isfinite(curve.time_s[i]) || !std::isfinite(curve.elongation_um[i]))
      throw InputError("curve: sample " + std::to_string(i) + " is not finite");
    if (i > 0 && !(curve.time_s[i] > curve.time_s[i - 1]))
      throw InputError("curve: time at sample " + std::to_string(i) +
                       " does not increase: times must be strictly increasing");
  }
  if (!(curve.time_s.back() > 0))
    throw InputError("curve: last time " + std::to_string(curve.time_s.back()) +
                     " s: the curve must extend past t = 0");
}

struct DataStart {
  double max_um;
  double settle_s;
  double t_lo;  // smallest admissible settle time
  double t_hi;  // largest admissible settle time
};

DataStart StartFromData(const ElongationCurve& curve) {
  DataStart s{};
  s.max_um = *std::max_element(curve.elongation_um.begin(), curve.elongation_um.end());
  s.max_um = std::max(s.max_um, 1e-9);
  s.t_hi = curve.time_s.back();
  // Smallest positive sample time (or a small fraction of the span when all times are > 0).
  s.t_lo = s.t_hi * 1e-3;
  for (double t : curve.time_s)
    if (t > 0) {
      s.t_lo = std::min(t, s.t_lo > 0 ? std::max(t, s.t_lo) : t);
      break;
    }
  s.settle_s = s.t_hi;
  for (std::size_t i = 0; i < curve.size(); ++i)
    if (curve.elongation_um[i] >= 0.98 * s.max_um && curve.time_s[i] > 0) {
      s.settle_s = curve.time_s[i];
      break;
    }
  s.settle_s = std::clamp(s.settle_s, s.t_lo, s.t_hi);
  return s;
}

std::vector<std::string> Names(CurveModel m) {
  switch (m) {
    case CurveModel::kArctan:
      return {"max_elongation_um", "settle_time_s", "shape_k", "time_exponent"};
    case CurveModel::kParabola:
      return {"max_elongation_um", "settle_time_s", "initial_slope_um_per_s"};
    case CurveModel::kSine:
      return {"max_elongation_um", "settle_time_s"};
  }
  return {};
}

}  // namespace

std::string ToString(CurveModel m) {
  switch (m) {
    case CurveModel::kArctan:
      return "arctan";
    case CurveModel::kParabola:
      return "parabola";
    case CurveModel::kSine:
      return "sine";
  }
  return "unknown";
}

CurveModel ParseCurveModel(const std::string& s) {
  for (CurveModel m : kAllCurveModels)
    if (ToString(m) == s) return m;
  throw InputError("curve model '" + s + "': must be one of arctan, parabola, sine");
}

double EvaluateModel(CurveModel model, const Eigen::VectorXd& p, double t, Eigen::VectorXd* grad) {
  const double big_l = p[0], ts = p[1];
  if (grad != nullptr) grad->setZero(p.size());
  if (t <= 0) return 0.0;
  switch (model) {
    case CurveModel::kArctan: {
      const ArctanCurve c{big_l, ts, p[2], p[3]};
      if (grad != nullptr)
        c.ParameterGradient(t, &(*grad)[0], &(*grad)[1], &(*grad)[2], &(*grad)[3]);
      return c.ElongationUm(t);
    }
    case CurveModel::kParabola: {
      const double b = p[2];
      if (t >= ts) {
        if (grad != nullptr) (*grad)[0] = 1.0;
        return big_l;
      }
      const double r = t / ts;
      if (grad != nullptr) {
        (*grad)[0] = r * r;
        // d/dts [(L - b ts) t^2 / ts^2] = -b t^2/ts^2 - 2 (L - b ts) t^2 / ts^3
        (*grad)[1] = -b * r * r - 2.0 * (big_l - b * ts) * r * r / ts;
        (*grad)[2] = t - ts * r * r;
      }
      return b * t + (big_l - b * ts) * r * r;
    }
    case CurveModel::kSine: {
      if (t >= ts) {
        if (grad != nullptr) (*grad)[0] = 1.0;
        return big_l;
      }
      const double arg = kPi * t / (2.0 * ts);
      if (grad != nullptr) {
        (*grad)[0] = std::sin(arg);
        (*grad)[1] = -big_l * std::cos(arg) * arg / ts;
      }
      return big_l * std::sin(arg);
    }
  }
  return 0.0;
}

double CurveFit::Evaluate(double t_s) const { return EvaluateModel(model, parameters, t_s); }

Features CurveFit::FittedFeatures() const { return {parameters[0], parameters[1]}; }

ArctanCurve CurveFit::AsArctan() const {
  if (model != CurveModel::kArctan)
    throw InputError("curve fit of model '" + ToString(model) + "' is not an arctan curve");
  return ArctanCurve{parameters[0], parameters[1], parameters[2], parameters[3]};
}

void GoodnessOfFit(const ElongationCurve& curve, const std::function<double(double)>& model_um,
                   double* r_squared, double* rms_residual_um, double* max_abs_residual_um) {
  const std::size_t n = curve.size();
  double mean = 0;
  for (double v : curve.elongation_um) mean += v;
  mean /= static_cast<double>(n);
  double ss_res = 0, ss_tot = 0, max_abs = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = curve.elongation_um[i] - model_um(curve.time_s[i]);
    ss_res += e * e;
    ss_tot += (curve.elongation_um[i] - mean) * (curve.elongation_um[i] - mean);
    max_abs = std::max(max_abs, std::abs(e));
  }
  if (r_squared != nullptr)
    *r_squared = ss_tot > 0 ? 1.0 - ss_res / ss_tot : (ss_res == 0 ? 1.0 : 0.0);
  if (rms_residual_um != nullptr) *rms_residual_um = std::sqrt(ss_res / static_cast<double>(n));
  if (max_abs_residual_um != nullptr) *max_abs_residual_um = max_abs;
}

CurveFit FitCurveModel(const ElongationCurve& curve, CurveModel model,
                       const CurveFitOptions& options) {
  CheckCurve(curve);
  const DataStart start = StartFromData(curve);
  CurveFit fit;
  fit.model = model;
  fit.parameter_names = Names(model);
  const auto n_par = static_cast<Eigen::Index>(fit.parameter_names.size());
  Eigen::VectorXd p(n_par), lower(n_par), upper(n_par);
  const double l_hi = 10.0 * std::max(std::abs(start.max_um), 1e-9) + 1.0;
  p[0] = start.max_um;
  p[1] = start.settle_s;
  lower[0] = 0.0;
  upper[0] = l_hi;
  lower[1] = start.t_lo;
  upper[1] = start.t_hi;
  if (model == CurveModel::kArctan) {
    p[2] = std::clamp(options.initial_shape_k, kMinShapeK, kMaxShapeK);
    lower[2] = kMinShapeK;
    upper[2] = kMaxShapeK;
    p[3] = std::clamp(options.initial_time_exponent, kMinTimeExponent, kMaxTimeExponent);
    lower[3] = kMinTimeExponent;
    upper[3] = kMaxTimeExponent;
  } else if (model == CurveModel::kParabola) {
    p[2] = 2.0 * start.max_um / start.settle_s;
    lower[2] = 0.0;
    upper[2] = kInf;
  }
  LmOptions lm = options.lm;
  lm.lower_bounds = lower;
  lm.upper_bounds = upper;
  const int m = static_cast<int>(curve.size());
  auto residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
    Eigen::VectorXd g(x.size());
    for (int i = 0; i < m; ++i) {
      (*r)[i] = EvaluateModel(model, x, curve.time_s[i], jac != nullptr ? &g : nullptr) -
                curve.elongation_um[i];
      if (jac != nullptr) jac->row(i) = g.transpose();
    }
  };
  fit.summary = SolveLeastSquares(residual, m, /*analytic_jacobian=*/true, &p, lm);
  fit.parameters = p;
  fit.samples = curve.size();
  GoodnessOfFit(
      curve, [&](double t) { return fit.Evaluate(t); }, &fit.r_squared, &fit.rms_residual_um,
      &fit.max_abs_residual_um);
  return fit;
}

std::vector<CurveFit> FitAllModels(const ElongationCurve& curve, const CurveFitOptions& options) {
  std::vector<CurveFit> fits;
  for (CurveModel m : kAllCurveModels) fits.push_back(FitCurveModel(curve, m, options));
  return fits;
}

namespace {

// LM setup shared by the single and the pooled shape fits: x = (k, p) within the bounds, or x = (k)
// when p is held at `fixed_p` (> 0).
LmOptions ShapeLmOptions(const CurveFitOptions& options, double fixed_p, Eigen::VectorXd* x) {
  const bool free_p = !(fixed_p > 0);
  x->resize(free_p ? 2 : 1);
  (*x)[0] = std::clamp(options.initial_shape_k, kMinShapeK, kMaxShapeK);
  LmOptions lm = options.lm;
  lm.lower_bounds = Eigen::VectorXd::Constant(x->size(), kMinShapeK);
  lm.upper_bounds = Eigen::VectorXd::Constant(x->size(), kMaxShapeK);
  if (free_p) {
    (*x)[1] = std::clamp(options.initial_time_exponent, kMinTimeExponent, kMaxTimeExponent);
    lm.lower_bounds[1] = kMinTimeExponent;
    lm.upper_bounds[1] = kMaxTimeExponent;
  }
  return lm;
}

// Residuals (model - data) * weight of one curve for shape x (see ShapeLmOptions), written from
// row `row` on.
void ShapeResiduals(const ElongationCurve& curve, const ArctanCurve& base, double weight,
                    double fixed_p, const Eigen::VectorXd& x, Eigen::Index row, Eigen::VectorXd* r,
                    Eigen::MatrixXd* jac) {
  ArctanCurve c = base;
  c.shape_k = x[0];
  c.time_exponent = x.size() > 1 ? x[1] : fixed_p;
  for (std::size_t i = 0; i < curve.size(); ++i, ++row) {
    (*r)[row] = weight * (c.ElongationUm(curve.time_s[i]) - curve.elongation_um[i]);
    if (jac != nullptr) {
      double dl, dt, dk, dp;
      c.ParameterGradient(curve.time_s[i], &dl, &dt, &dk, &dp);
      (*jac)(row, 0) = weight * dk;
      if (x.size() > 1) (*jac)(row, 1) = weight * dp;
    }
  }
}

// The pooled fit (see ShapeCalibration) with p free (fixed_p <= 0) or held; returns (k, p).
Eigen::Vector2d PooledShape(const std::vector<ElongationCurve>& curves,
                            const std::vector<ArctanCurve>& bases,
                            const std::vector<double>& weights, const CurveFitOptions& options,
                            double fixed_p, LmSummary* summary) {
  Eigen::Index rows = 0;
  for (const auto& c : curves) rows += static_cast<Eigen::Index>(c.size());
  auto residual = [&](const Eigen::VectorXd& x, Eigen::VectorXd* r, Eigen::MatrixXd* jac) {
    Eigen::Index row = 0;
    for (std::size_t i = 0; i < curves.size(); ++i) {
      ShapeResiduals(curves[i], bases[i], weights[i], fixed_p, x, row, r, jac);
      row += static_cast<Eigen::Index>(curves[i].size());
    }
  };
  Eigen::VectorXd x;
  const LmOptions lm = ShapeLmOptions(options, fixed_p, &x);
  *summary = SolveLeastSquares(residual, static_cast<int>(rows), true, &x, lm);
  return {x[0], x.size() > 1 ? x[1] : fixed_p};
}

}  // namespace

ShapeFit FitShape(const ElongationCurve& curve, const Features& features,
                  const CurveFitOptions& options) {
  CheckCurve(curve);
  const ArctanCurve base =
      ArctanCurve::FromFeatures(features, kDefaultShapeK, kDefaultTimeExponent);
  ShapeFit fit;
  const Eigen::Vector2d x = PooledShape({curve}, {base}, {1.0}, options, 0.0, &fit.summary);
  fit.shape_k = x[0];
  fit.time_exponent = x[1];
  const ArctanCurve c = ArctanCurve::FromFeatures(features, x[0], x[1]);
  GoodnessOfFit(
      curve, [&](double t) { return c.ElongationUm(t); }, &fit.r_squared, &fit.rms_residual_um,
      nullptr);
  return fit;
}

ShapeCalibration CalibrateShape(const std::vector<ElongationCurve>& curves,
                                const std::vector<Features>& features,
                                const CurveFitOptions& options) {
  if (curves.empty()) throw InputError("shape calibration: no curves");
  if (curves.size() != features.size())
    throw InputError("shape calibration: " + std::to_string(curves.size()) + " curves but " +
                     std::to_string(features.size()) + " feature pairs");
  ShapeCalibration cal;
  std::vector<ArctanCurve> bases;
  std::vector<double> weights;
  for (std::size_t i = 0; i < curves.size(); ++i) {
    CheckCurve(curves[i]);
    if (!(features[i].max_elongation_um > 0))
      throw InputError("shape calibration: curve " + std::to_string(i) +
                       " has max_elongation_um = " + std::to_string(features[i].max_elongation_um) +
                       ": must be > 0 (curves are normalized by it)");
    bases.push_back(ArctanCurve::FromFeatures(features[i], kDefaultShapeK, kDefaultTimeExponent));
    weights.push_back(
        1.0 / (features[i].max_elongation_um * std::sqrt(static_cast<double>(curves[i].size()))));
    cal.fits.push_back(FitShape(curves[i], features[i], options));
  }
  const Eigen::Vector2d x = PooledShape(curves, bases, weights, options, 0.0, &cal.summary);
  cal.shape_k = x[0];
  cal.time_exponent = x[1];
  LmSummary plain_summary;
  cal.plain_shape_k = PooledShape(curves, bases, weights, options, 1.0, &plain_summary)[0];
  std::vector<double> ks, ps, r2s, rms, plain_rms;
  for (std::size_t i = 0; i < curves.size(); ++i) {
    ks.push_back(cal.fits[i].shape_k);
    ps.push_back(cal.fits[i].time_exponent);
    const ArctanCurve c = ArctanCurve::FromFeatures(features[i], x[0], x[1]);
    const ArctanCurve plain = ArctanCurve::FromFeatures(features[i], cal.plain_shape_k, 1.0);
    double r2 = 0, e = 0, e_plain = 0;
    GoodnessOfFit(
        curves[i], [&](double t) { return c.ElongationUm(t); }, &r2, &e, nullptr);
    GoodnessOfFit(
        curves[i], [&](double t) { return plain.ElongationUm(t); }, nullptr, &e_plain, nullptr);
    r2s.push_back(r2);
    rms.push_back(e);
    plain_rms.push_back(e_plain);
  }
  cal.min_shape_k = *std::min_element(ks.begin(), ks.end());
  cal.max_shape_k = *std::max_element(ks.begin(), ks.end());
  cal.min_time_exponent = *std::min_element(ps.begin(), ps.end());
  cal.max_time_exponent = *std::max_element(ps.begin(), ps.end());
  cal.median_r_squared = Median(r2s);
  cal.median_rms_residual_um = Median(rms);
  cal.plain_median_rms_residual_um = Median(plain_rms);
  return cal;
}

}  // namespace whirl::fit
