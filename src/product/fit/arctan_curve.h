#pragma once
// The arctangent elongation curve of the unmachined section (Li, Ma and Jiang, "Thermal
// elongation prediction of whirlwind hard milling ballscrew based on BP neural network", section
// 3: "the dynamic part is fitted with an arctangent function, the plateau with a line").
//
//   l(t) = L * atan(k (t / t_s)^p) / atan(k)     for 0 <= t < t_s
//   l(t) = L                                     for t >= t_s          (and l(t) = 0 for t < 0)
//
//   L   = max_elongation_um  (plateau, um)         t_s = settle_time_s (s)
//   k   = shape_k (dimensionless, > 0): how sharply the curve bends.
//   p   = time_exponent (dimensionless, in [0.5, 1]): the arctangent's argument grows as t^p.
//         p = 1 is the plain arctangent in time, l = L atan(k t/t_s)/atan(k).
//
// Why the exponent. Not a sqrt(t) start: in the simulator's section-mean model the initial slope
// is finite, alpha q / (2 rho c A) = 0.324 um/s for the reference screw (half the source's heat
// lands in the unmachined section). What p < 1 compensates is that this slope falls fast (to
// 0.21 um/s within 10 s, as the heat spreads ahead of the cut), while a plain arctangent through the
// same L and t_s starts at only 0.21 um/s and bends later; p < 1 makes the start steep and the bend
// early (its infinite slope at t = 0 matters only in the first seconds). k and p are a pooled
// least-squares fit over simulated curves (whirl fit --simulated 25); what that fit and the
// exponent gain is measured in docs/methods.md ("Build the curve"). The
// network still only predicts L and t_s; k and p are properties of the process family, fitted once
// (kDefaultShapeK, kDefaultTimeExponent).
//
// Slope: l'(t) = L k p (t/t_s)^(p-1) / (t_s atan(k) (1 + k^2 (t/t_s)^(2p))). At t = 0 it is
// L k/(t_s atan k) for p = 1 and infinite for p < 1; just before t_s it is
// L k p / (t_s atan(k) (1 + k^2)), after t_s it is 0 (the curve is continuous at t_s, its slope
// jumps; the jump is small against the initial slope: 1/(1 + k^2) of it for p = 1).
// For p in (0, 1] the curve is concave on [0, t_s] (both factors of l' decrease), which the
// compensation-point placement (interp/breakpoints.h) relies on for fewest points.
#include <nlohmann/json.hpp>
#include <string>

#include "core/process.h"

namespace whirl::fit {

/// Default shape k and time exponent p: the pooled least-squares fit of (k, p) with L and t_s
/// fixed to the simulator's features (sim::ExtractFeatures), each curve normalized by L and its
/// sample count so that every curve weighs the same (fit::CalibrateShape), over 25 undisturbed
/// simulated curves spread over the paper's training ranges (design seed 1). Reproduce with
///   whirl fit --simulated 25          (src/lab/compare/curve_study.h)
/// tests/compare/test_curve_study.cpp checks both against a freshly simulated set.
inline constexpr double kDefaultShapeK = 4.33;
inline constexpr double kDefaultTimeExponent = 0.882;

/// Bounds accepted for the shape parameter (validation and fitting).
inline constexpr double kMinShapeK = 1e-3;
inline constexpr double kMaxShapeK = 1e3;
/// Bounds accepted for the time exponent: above 1 the curve would start convex (S-shaped), which
/// neither the physics (heat input from t = 0) nor the compensation-point placement expects.
/// Below 0.5 the start is so steep that checking a compensation plan against the curve needs
/// impractically fine grids (interp/breakpoints.h), and already below about 0.7 the first
/// compensation segment can be steeper than MD32760 allows (the plan then fails with an error
/// naming the segment); the simulated curves give 0.87 to 0.89.
inline constexpr double kMinTimeExponent = 0.5;
inline constexpr double kMaxTimeExponent = 1.0;

struct ArctanCurve {
  double max_elongation_um = 0;     ///< L, plateau elongation, um (>= 0)
  double settle_time_s = 0;         ///< t_s, time at which the plateau is reached, s (> 0)
  double shape_k = kDefaultShapeK;  ///< k, dimensionless, in [kMinShapeK, kMaxShapeK]
  /// p, dimensionless, in [kMinTimeExponent, kMaxTimeExponent]
  double time_exponent = kDefaultTimeExponent;

  /// l(t) in um; t in s from the start of the cut. 0 for t <= 0, L for t >= t_s.
  double ElongationUm(double t_s) const;
  /// dl/dt in um/s: left derivative at t_s, 0 for t > t_s and for t < 0; at t = 0 the right
  /// derivative (+infinity when p < 1 and L > 0).
  double SlopeUmPerS(double t_s) const;
  /// Partial derivatives of l(t) with respect to (L, t_s, k) and, if d_l_d_p is given, p; for
  /// fitting.
  void ParameterGradient(double t_s, double* d_l_d_max, double* d_l_d_settle, double* d_l_d_k,
                         double* d_l_d_p = nullptr) const;

  /// Curve with L and t_s from the two features, shape k and time exponent p.
  static ArctanCurve FromFeatures(const Features& features, double shape_k = kDefaultShapeK,
                                  double time_exponent = kDefaultTimeExponent);
  Features ToFeatures() const { return {max_elongation_um, settle_time_s}; }

  /// "arctan L=30.1234 um, t_s=301.25 s, k=4.3300, p=0.8820": for provenance lines.
  std::string Describe() const;

  /// Throws InputError (naming `what`, the field, the value and the rule) unless L >= 0 and
  /// finite, t_s > 0 and finite, k within [kMinShapeK, kMaxShapeK], p within
  /// [kMinTimeExponent, kMaxTimeExponent].
  void Validate(const std::string& what = "arctan curve") const;
};

/// The formula as written in files and --help: "l(t) = L atan(k (t/t_s)^p)/atan(k) for t < t_s,
/// L after".
inline constexpr const char* kArctanFormula =
    "l(t) = L atan(k (t/t_s)^p)/atan(k) for t < t_s, L after";

/// {"model": "arctan", "formula", "max_elongation_um", "settle_time_s", "shape_k",
/// "time_exponent"}.
void to_json(nlohmann::json& j, const ArctanCurve& c);

}  // namespace whirl::fit
