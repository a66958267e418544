#pragma once
// The arctangent elongation curve of the unmachined section (REFERENCE.md section 1; paper seed
// 002, section 3: "the dynamic part is fitted with an arctangent function, the plateau with a
// line").
//
//   l(t) = L * atan(k t / t_s) / atan(k)     for 0 <= t < t_s
//   l(t) = L                                 for t >= t_s          (and l(t) = 0 for t < 0)
//
//   L   = max_elongation_um  (plateau, um)         t_s = settle_time_s (s)
//   k   = shape_k (dimensionless, > 0): how sharply the curve bends. The slope at the start is
//         l'(0) = L k / (t_s atan k); just before t_s it is l'(t_s-) = L k / (t_s atan(k) (1 +
//         k^2)).
//
// The two network features fix L and t_s; k is a property of the process family, fitted once from
// simulated curves (kDefaultShapeK). The curve is continuous at t_s (l(t_s-) = L) but its slope
// jumps from l'(t_s-) to 0. The jump is small compared with the initial slope for k of a few
// (ratio 1/(1+k^2): 1/10 at k = 3), which is what makes the piecewise form a fair model of a curve
// that "is essentially constant" after t_s (paper Fig. 1); SlopeUmPerS returns the left slope at
// t_s, 0 after it.
#include "core/process.h"

namespace whirl::fit {

/// Default shape parameter k: the median of k fitted with L and t_s fixed to the simulator's
/// features (sim::ExtractFeatures) over 25 undisturbed simulated curves spread over the paper's
/// training ranges: 5.62 (range 5.10 to 5.91, median R^2 0.998). Reproduce with
///   whirl fit --simulated 25          (src/fit/simulated_fits.h)
/// tests/fit/test_simulated_fits.cpp checks it is near the median of a freshly simulated set.
/// With k = 5.62 the slope just before t_s is 1/(1 + k^2) = 3 % of the initial slope.
inline constexpr double kDefaultShapeK = 5.62;

/// Bounds accepted for the shape parameter (validation and fitting).
inline constexpr double kMinShapeK = 1e-3;
inline constexpr double kMaxShapeK = 1e3;

struct ArctanCurve {
  double max_elongation_um = 0;     ///< L, plateau elongation, um (>= 0)
  double settle_time_s = 0;         ///< t_s, time at which the plateau is reached, s (> 0)
  double shape_k = kDefaultShapeK;  ///< k, dimensionless, in [kMinShapeK, kMaxShapeK]

  /// l(t) in um; t in s from the start of the cut. 0 for t <= 0, L for t >= t_s.
  double ElongationUm(double t_s) const;
  /// dl/dt in um/s: left derivative at t_s, 0 for t > t_s and for t < 0.
  double SlopeUmPerS(double t_s) const;
  /// Partial derivatives of l(t) with respect to (L, t_s, k), for fitting.
  void ParameterGradient(double t_s, double* d_l_d_max, double* d_l_d_settle,
                         double* d_l_d_k) const;

  /// Curve with L and t_s from the two features and shape k.
  static ArctanCurve FromFeatures(const Features& features, double shape_k = kDefaultShapeK);
  Features ToFeatures() const { return {max_elongation_um, settle_time_s}; }

  /// Throws InputError (naming `what`, the field, the value and the rule) unless L >= 0 and
  /// finite, t_s > 0 and finite, k within [kMinShapeK, kMaxShapeK].
  void Validate(const std::string& what = "arctan curve") const;
};

}  // namespace whirl::fit
