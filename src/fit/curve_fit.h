#pragma once
// Fitting elongation-curve models to simulated or measured curves with the LM solver
// (src/fit/levenberg_marquardt.h). Paper seed 002 section 3 compares sine, parabola and arctangent
// fits of the dynamic part (plateau: a line) and finds the arctangent best; this module repeats
// that comparison. Every model is 0 at t = 0, reaches its plateau L at t_s and stays there:
//
//   arctan   (L, t_s, k):  l = L atan(k t/t_s)/atan(k)                 (fit/arctan_curve.h)
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
  /// Start value of k for the arctan fit (the start of L and t_s comes from the data: L0 = largest
  /// value, t_s0 = first time the curve reaches 98 % of L0).
  double initial_shape_k = kDefaultShapeK;
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

/// Fit of the shape k only, with L and t_s fixed (the features as the simulator or the network
/// defines them) so that ArctanCurve::FromFeatures(features, k) follows the curve best.
struct ShapeFit {
  double shape_k = 0;
  double r_squared = 0;
  double rms_residual_um = 0;
  LmSummary summary;
};
ShapeFit FitShapeK(const ElongationCurve& curve, const Features& features,
                   const CurveFitOptions& options = {});

/// Median of the fitted k over several curves (each with its features): how kDefaultShapeK is
/// derived. Throws InputError for empty input or size mismatch.
struct ShapeCalibration {
  double median_shape_k = 0;
  double min_shape_k = 0, max_shape_k = 0;
  double median_r_squared = 0;
  std::vector<ShapeFit> fits;
};
ShapeCalibration CalibrateShapeK(const std::vector<ElongationCurve>& curves,
                                 const std::vector<Features>& features,
                                 const CurveFitOptions& options = {});

/// Goodness of fit of any predictor on a curve: R^2 and RMS as defined above.
void GoodnessOfFit(const ElongationCurve& curve, const std::function<double(double)>& model_um,
                   double* r_squared, double* rms_residual_um, double* max_abs_residual_um);

}  // namespace whirl::fit
