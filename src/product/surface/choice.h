#pragma once
// Choosing between the cubic polynomial and the B-spline (the book: fit where the field is smooth
// and of low order; interpolate where it has local bumps, because a forced fit oscillates, most at
// the edges: Runge's phenomenon).
//
// On one set of measured points:
//   - the leave-one-out (LOO) error of each method per point (cubic.h: one point left out;
//     bspline.h: its row or its column left out, the only way to keep a rectangular grid);
//   - compared on the points where both are defined ("common points": not the grid's corners),
//     RMS and max |.|, um; the recommendation is the lower common LOO RMS (the cubic on a tie, or
//     when the B-spline cannot run: scattered points, too few lines);
//   - the oscillation note for the cubic, raised when either
//       edge LOO RMS > edge_ratio x interior LOO RMS (edge points: on the bounding box), or
//       the cubic leaves the measured range [min, max] on a samples x samples map of the box by
//       more than overshoot_fraction x (max - min) (overshoot_um below; a cubic overshoots where
//       it swings between points, mostly at the edges),
//     and in either case by more than min_excess_um (so noise-free fits are never flagged).
#include <string>
#include <vector>

#include "surface/surface.h"

namespace whirl::surface {

struct ChoiceOptions {
  int degree = 3;                   ///< B-spline degree, 1..kMaxDegree
  double edge_ratio = 1.5;          ///< edge/interior LOO RMS ratio that flags oscillation (> 1)
  double overshoot_fraction = 0.1;  ///< overshoot / measured range that flags it (> 0)
  int map_samples = 101;            ///< map points per direction for the overshoot (2..1001)
  double min_excess_um = 0.5;       ///< smallest excess that flags oscillation, um (>= 0)
  void Validate() const;
};

struct MethodComparison {
  ChoiceOptions options;
  bool cubic_available = false, bspline_available = false;
  std::string cubic_refusal, bspline_refusal;  ///< why a method could not run (its InputError)
  std::vector<double> cubic_loo_um, bspline_loo_um;  ///< per point; NaN: undefined
  ErrorStats cubic_loo, bspline_loo;                 ///< over each method's defined points
  ErrorStats cubic_loo_common, bspline_loo_common;   ///< over the common points
  ErrorStats cubic_loo_edge, cubic_loo_interior;     ///< cubic LOO on edge / interior points
  double measured_range_um = 0;                      ///< max - min of the measured errors
  double cubic_overshoot_um = 0;  ///< how far the cubic leaves [min, max] over the box (>= 0)
  bool cubic_oscillates = false;
  Method recommended = Method::kCubic;
  std::string reason;  ///< one sentence with the numbers compared
  std::string note;    ///< the oscillation note (empty if none)
};

/// Compares both methods; InputError only if neither can run (naming both reasons).
MethodComparison CompareMethods(const std::vector<SurfacePoint>& points,
                                const ChoiceOptions& options = {});

nlohmann::json ComparisonToJson(const MethodComparison& c);
std::string FormatComparisonText(const MethodComparison& c);

}  // namespace whirl::surface
