#pragma once
// The lead deviation a cut leaves behind, from the elongation of the unmachined section and the
// compensation applied while cutting (Li, Ma and Jiang: the unmachined section's elongation
// displaces the groove).
//
// Geometry: the thread is cut from its start (free end) towards the chuck at constant axial feed
// v, so the cut point at time t is x = v t along the thread. The unmachined section (cut point to
// chuck) has grown by e(t) um, which shifts the material at the cut point away from the chuck; the
// control shifts the tool by the compensation c(t) um (positive = the same direction as the
// elongation it cancels). After cooling, the groove cut at time t lies (e(t) - c(t)) um further
// towards the chuck than specified. Measured from the thread start (the first groove), the travel
// deviation is (sign convention of lead/lead.h: actual minus specified travel)
//
//   d(x) = [e(t) - c(t)] - [e(0) - c(0)],      t = x / v,  0 <= x <= thread_length_mm
//
// A constant c shifts nothing; only the change of e - c along the cut makes lead error.
#include <functional>

#include "lead/lead.h"
#include "core/curve.h"

namespace whirl::compare {

/// Compensation applied at time t_s from the start of the cut, um.
using CompensationFunction = std::function<double(double t_s)>;

struct CutOptions {
  /// Spacing of the lead samples along the thread, mm (> 0). 0 = automatic: min(1 mm, lead/10),
  /// fine enough to resolve v_2pi (one lead of travel).
  double sample_step_mm = 0.0;
};

/// d(x) at x = 0, step, 2 step, ..., thread_length_mm (the last sample exactly at the end).
/// e(t) is linearly interpolated in `truth` (held at its first value before its first sample).
/// InputError: non-positive or non-finite feed, length, lead or step; a truth curve that stops
/// before the cut ends (more than one of its own sample steps short of thread_length / feed).
lead::LeadDeviation CutLeadDeviation(const ElongationCurve& truth,
                               const CompensationFunction& compensation_um, double axial_feed_mm_s,
                               double thread_length_mm, double lead_mm,
                               const CutOptions& options = {});

/// No compensation: c(t) = 0.
CompensationFunction NoCompensation();

}  // namespace whirl::compare
