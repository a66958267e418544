#pragma once
// Documented synthetic thermal-error fields over a worktable. No public measurements of a whole
// table exist, so tests and the demo use these (the book shows only smooth fields; the bump is the
// rough case its B-spline is for). With s = x / length_x, t = y / length_y in [0, 1]:
//
//   smooth(x, y) = 10 + 10 s + 6 t + 4 s^2 + 3 s t - 2 t^2 + 5 s^3 + 2 s t^2   um
//                  (linear, quadratic and cubic parts; 10 um at (0, 0), 38 um at (1, 1))
//   bump(x, y)   = smooth(x, y) + A exp(-((x - x0)^2 + (y - y0)^2) / (2 sigma^2))
//                  A = bump_um (default 15 um), (x0, y0) = (0.7 length_x, 0.35 length_y),
//                  sigma = bump_sigma_fraction * length_x (default 0.1): a local hot spot
//   measured     = field + noise, noise ~ Normal(0, noise_um^2) (default 1 um), drawn with
//                  core/random.h's Rng(seed) (deterministic across standard libraries), row
//                  by row.
// Points: an nx x ny grid from (0, 0) to (length_x, length_y), evenly spaced, row by row (y outer).
#include <cstdint>
#include <string>
#include <vector>

#include "surface/bspline.h"
#include "surface/points.h"

namespace whirl::synthetic {

enum class SyntheticField { kSmooth, kBump };
std::string ToString(SyntheticField f);                  ///< "smooth" / "bump"
SyntheticField ParseSyntheticField(const std::string&);  ///< InputError for other strings

struct SyntheticOptions {
  SyntheticField field = SyntheticField::kSmooth;
  double length_x_mm = 800;          ///< table travel in X, mm (> 0)
  double length_y_mm = 500;          ///< table travel in Y, mm (> 0)
  int nx = 9;                        ///< grid columns (2..kMaxGridLines), nx * ny <= kMaxPoints
  int ny = 7;                        ///< grid rows (2..kMaxGridLines), nx * ny <= kMaxPoints
  double noise_um = 1.0;             ///< standard deviation of the noise, um (0..10)
  double bump_um = 15;               ///< bump amplitude, um (0..100)
  double bump_sigma_fraction = 0.1;  ///< bump width / length_x (0.01..1)
  std::uint64_t seed = 1;
  void Validate() const;  ///< InputError naming the field
};

/// The noise-free field at (x, y), um.
double SyntheticErrorUm(const SyntheticOptions& o, double x_mm, double y_mm);

/// The measured grid (field + noise).
std::vector<surface::SurfacePoint> SyntheticPoints(const SyntheticOptions& o);

/// '#' provenance lines for a points file: the field, its formula and the options.
std::vector<std::string> SyntheticProvenance(const SyntheticOptions& o);

}  // namespace whirl::synthetic
