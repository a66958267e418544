#pragma once
// Circle-test diagnostics of a ball-bar trace (ISO 230-4 style; Shang et al., 2.1-2.3, show the
// thermal errors that appear in these traces: spindle / Z-guide parallelism in the XZ semicircle,
// the scale mismatch of an axis whose scale grows with heat, the cyclic error of a ball screw).
//
// Trace CSV: header `angle_deg,deviation_um` ('#' comments), one row per sample:
//   angle_deg     theta, from axis 1 towards axis 2 of the plane (XY: from +X to +Y; XZ: from +X
//                 to +Z; YZ: from +Y to +Z), degrees, strictly increasing, span <= 360 degrees
//   deviation_um  measured minus nominal radius, um (positive = outwards)
// At least 16 samples and a span of at least 180 degrees (an XZ or YZ semicircle), at most
// kMaxTraceSamples.
//
// Model (first order in the errors, R the nominal radius; u = axis-1 and v = axis-2 offsets from
// the circle's centre, u = R cos theta, v = R sin theta; a point moves by (du, dv) and the radius
// by du cos theta + dv sin theta). Linear least squares in the coefficients:
//   dr(theta) = r0                                   radius offset (bar length, mean scale), um
//             + e1 cos theta + e2 sin theta          centre offset of axis 1 / axis 2, um
//             + c2 cos 2 theta                       scale mismatch: du = s1 u, dv = s2 v gives
//                                                    c2 = R (s1 - s2) / 2, reported as
//                                                    s1 - s2 = 2 c2 / R in um/m
//             + q2 sin 2 theta                       squareness: du = alpha v (axis 2's travel has
//                                                    an axis-1 component alpha; the axes enclose
//                                                    90 deg - alpha), q2 = alpha R / 2, reported
//                                                    as alpha = 2 q2 / R in urad
//             + cos theta [a1 sin(k1 u) + b1 cos(k1 u)]   cyclic error of axis 1, k1 = 2 pi / p1:
//                                                    du = A1 sin(k1 u + phi1), A1 = hypot(a1, b1),
//                                                    phi1 = atan2(b1, a1)
//             + sin theta [a2 sin(k2 v) + b2 cos(k2 v)]   the same for axis 2 (period p2)
// The cyclic terms are fitted only for a period given (> 0; for a ball screw its lead, mm).
// XZ parallelism of the spindle to the Z guide: the tool ball rides on the Z slide, so the bar sees
// the Z travel against the X travel only; with the spindle axis square to the X travel (or its
// measured tram angle t given, urad), the parallelism of the Z travel to the spindle axis is
//   beta = alpha_XZ - t   (urad; a Z travel leaning towards +X as Z rises is positive).
// It is the same coefficient as the XZ squareness (the trace cannot tell them apart); it is
// reported under both names in the XZ plane. Each coefficient comes with its standard error from
// the residual (sigma^2 (A'A)^-1). Also: residual RMS and max (um) and the circular deviation G =
// max - min of the trace after removing the least-squares centre (ISO 230-4, with the LSC centre
// instead of the minimum zone, um). Semicircles (XZ, YZ): over 0..180 degrees the radius offset,
// the axis-2 centre offset and the scale mismatch are correlated, so their standard errors are 5-7
// times those of a full circle (R 125 mm, 0.1 um noise, 1441 samples: scale mismatch sd 0.29 um/m
// against 0.045 um/m on a full circle of 2880 samples); the squareness / parallelism is 3 times
// worse. Read the sd column. Not modelled: backlash, reversal spikes, servo mismatch
// (direction-dependent terms; fit each direction's trace separately).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace whirl::ballbar {

inline constexpr std::size_t kMaxTraceSamples = 1000000;

enum class Plane { kXY, kXZ, kYZ };
std::string ToString(Plane p);           ///< "XY", "XZ", "YZ"
Plane ParsePlane(const std::string& s);  ///< InputError for anything else (case-insensitive)

struct CircleTrace {
  std::string source;
  std::vector<double> angle_deg;
  std::vector<double> deviation_um;
  std::vector<std::string> comments;
};

CircleTrace ReadCircleTrace(const std::filesystem::path& path);
CircleTrace ParseCircleTrace(const std::string& text, const std::string& source);
std::string FormatCircleTrace(const CircleTrace& trace);

struct CircleOptions {
  Plane plane = Plane::kXY;
  double radius_mm = 100;         ///< nominal radius (bar length), mm (1..2000)
  double cyclic_period_1_mm = 0;  ///< period of axis 1's cyclic error, mm (0: not fitted)
  double cyclic_period_2_mm = 0;  ///< period of axis 2's cyclic error, mm (0: not fitted)
  double spindle_tram_urad = 0;   ///< XZ only: spindle axis tilt from square to X, urad
  void Validate() const;
};

/// A fitted quantity with its unit and standard error.
struct Term {
  std::string name;
  double value = 0;
  double sd = 0;
  std::string unit;
};

struct CircleDiagnostics {
  Plane plane = Plane::kXY;
  double radius_mm = 0;
  int samples = 0;
  double span_deg = 0;
  double radius_offset_um = 0;
  double centre_offset_1_um = 0, centre_offset_2_um = 0;
  double scale_mismatch_um_per_m = 0;  ///< s1 - s2
  double squareness_urad = 0;          ///< alpha
  double cyclic_amplitude_1_um = 0, cyclic_phase_1_deg = 0;
  double cyclic_amplitude_2_um = 0, cyclic_phase_2_deg = 0;
  double parallelism_urad = 0;  ///< XZ only: alpha - tram
  std::vector<Term> terms;      ///< every reported quantity with its sd, in order
  double residual_rms_um = 0, residual_max_um = 0;
  double circular_deviation_um = 0;  ///< G about the least-squares centre
};

/// Least-squares fit of the model above. InputError for too few samples, a span under 180
/// degrees, or terms the trace cannot separate (e.g. a cyclic period so long that it mimics the
/// centre offset): the message names the option.
CircleDiagnostics FitCircle(const CircleTrace& trace, const CircleOptions& options);

nlohmann::json ToJson(const CircleDiagnostics& d);

}  // namespace whirl::ballbar
