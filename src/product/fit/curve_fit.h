#pragma once
// Fitting elongation-curve models to simulated or measured curves with the LM solver
// (src/product/fit/levenberg_marquardt.h). Li, Ma and Jiang compare sine, parabola and arctangent
// fits of the dynamic part (plateau: a line) and finds the arctangent best; this module repeats
// that comparison. Every model is 0 at t = 0, reaches its plateau L at t_s and stays there:
//
//   arctan   (L, t_s, k, p): l = L atan(k (t/t_s)^p)/atan(k)           (fit/arctan_curve.h)
//   parabola (L, t_s, b):  l = b t + (L - b t_s)(t/t_s)^2   (general parabola through the origin
//                          reaching L at t_s; b = initial slope, um/s; b = 2L/t_s is the vertex
//                          form)
//   sine     (L, t_s):     l = L sin(pi t / (2 t_s))
//
// Goodness of fit: R^2 = 1 - SS_res/SS_tot; RMS residual = sqrt(SS_res / n), um.
#include <Eigen/Core>
#include <string>
#include <vector>

#include "core/curve.h"
#include "core/process.h"
#include "fit/arctan_curve.h"
#include "fit/levenberg_marquardt.h"

namespace whirl::fit {

enum class CurveModel { kArctan, kParabola, kSine };
std::string ToString(CurveModel m);                ///< "arctan", "parabola", "sine"
CurveModel ParseCurveModel(const std::string& s);  ///< InputError for other names
inline constexpr CurveModel kAllCurveModels[] = {CurveModel::kArctan, CurveModel::kParabola,
                                                 CurveModel::kSine};

struct CurveFitOptions {
  /// LM settings; bounds are set by the fitter (L in [0, 10 max|l| + 1], t_s within the recorded
  /// time span, k in [kMinShapeK, kMaxShapeK], b >= 0).
  /// The iteration limit is raised to 2000 and the relative cost-decrease tolerance to 1e-9: the
  /// settle time is a kink of every model, so the cost is only piecewise smooth in t_s (a kink
  /// wherever t_s crosses a sample); a model whose best t_s sits on a kink (the parabola, often)
  /// otherwise creeps along it with ever smaller accepted steps.
  LmOptions lm = [] {
    LmOptions o;
    o.max_iterations = 2000;
    o.cost_tolerance = 1e-9;
    return o;
  }();
  /// Start values of k and p for the arctan fits (the start of L and t_s comes from the data:
  /// L0 = largest value, t_s0 = first time the curve reaches 98 % of L0).
  double initial_shape_k = kDefaultShapeK;
  double initial_time_exponent = kDefaultTimeExponent;
};

struct CurveFit {
  CurveModel model = CurveModel::kArctan;
  std::vector<std::string> parameter_names;  ///< with units, e.g. "max_elongation_um"
  Eigen::VectorXd parameters;
  double r_squared = 0;            ///< 1 - SS_res/SS_tot (1 when SS_tot = 0 and SS_res = 0)
  double rms_residual_um = 0;      ///< sqrt(SS_res/n), um
  double max_abs_residual_um = 0;  ///< largest |data - model|, um
  std::size_t samples = 0;
  LmSummary summary;

  /// Model value at t (um).
  double Evaluate(double t_s) const;
  /// The fitted features (L, t_s).
  Features FittedFeatures() const;
  /// The arctan curve (model must be kArctan; otherwise InputError).
  ArctanCurve AsArctan() const;
};

/// Model value for parameters p (layout as in parameter_names) and its gradient (may be null).
double EvaluateModel(CurveModel model, const Eigen::VectorXd& p, double t_s,
                     Eigen::VectorXd* gradient = nullptr);

/// Fits one model to all samples (least squares on l). The curve needs >= 3 samples and positive
/// time span (InputError otherwise). Non-convergence is reported in summary, not thrown.
CurveFit FitCurveModel(const ElongationCurve& curve, CurveModel model,
                       const CurveFitOptions& options = {});

/// Fits the three models; the result is in kAllCurveModels order.
std::vector<CurveFit> FitAllModels(const ElongationCurve& curve,
                                   const CurveFitOptions& options = {});

/// Fit of the shape (k, p) only, with L and t_s fixed (the features as the simulator or the
/// network defines them) so that ArctanCurve::FromFeatures(features, k, p) follows the curve best
/// (least squares on l, bounds of arctan_curve.h).
struct ShapeFit {
  double shape_k = 0;
  double time_exponent = 0;
  double r_squared = 0;
  double rms_residual_um = 0;
  LmSummary summary;
};
ShapeFit FitShape(const ElongationCurve& curve, const Features& features,
                  const CurveFitOptions& options = {});

/// One (k, p) for a family of curves: how kDefaultShapeK and kDefaultTimeExponent are derived.
/// The pooled fit minimizes sum_i (1/m_i) sum_j ((l_i(t_j) - ArctanCurve(L_i, t_s,i, k, p)(t_j)) /
/// L_i)^2 over all curves i (m_i samples, features L_i, t_s,i fixed): every curve counts the same
/// whatever its size and sample count. The per-curve fits (FitShape) give the spread.
/// Throws InputError for empty input, size mismatch or a curve with L <= 0.
struct ShapeCalibration {
  double shape_k = 0;                                   ///< pooled k
  double time_exponent = 0;                             ///< pooled p
  LmSummary summary;                                    ///< of the pooled fit
  double min_shape_k = 0, max_shape_k = 0;              ///< range of the per-curve k
  double min_time_exponent = 0, max_time_exponent = 0;  ///< range of the per-curve p
  /// Median over the curves of R^2 and RMS residual (um) of the pooled (k, p) on each curve.
  double median_r_squared = 0;
  double median_rms_residual_um = 0;
  /// The same pooled fit with p held at 1 (the plain arctangent in time): its k and the median
  /// RMS residual (um) it leaves on the curves, for comparison.
  double plain_shape_k = 0;
  double plain_median_rms_residual_um = 0;
  std::vector<ShapeFit> fits;  ///< per curve
};
ShapeCalibration CalibrateShape(const std::vector<ElongationCurve>& curves,
                                const std::vector<Features>& features,
                                const CurveFitOptions& options = {});

/// Goodness of fit of any predictor on a curve: R^2 and RMS as defined above.
void GoodnessOfFit(const ElongationCurve& curve, const std::function<double(double)>& model_um,
                   double* r_squared, double* rms_residual_um, double* max_abs_residual_um);

}  // namespace whirl::fit
