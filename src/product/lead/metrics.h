#pragma once
// Lead-accuracy metrics of a travel-deviation curve, as ISO 3408-3 and the paper define them
// (Li, Ma and Jiang; ISO 3408-3). All values in micrometres, positions in millimetres.
//
// Definitions used here (x = position along the thread from its start, d(x) = travel deviation):
// - Useful travel l_u: [x0 + m, x_end - m] with m = LeadMetricOptions::end_margin_mm (the excess
//   travel l_e at each end; 0 = the whole measured/simulated thread).
// - Mean travel line: the least-squares line d ~ a + b x fitted to the samples inside l_u.
// - e_a = b * l_u: the actual mean travel deviation (rise of the mean travel line over l_u).
// - r(x) = d(x) - (a + b x): the deviation about the mean travel line.
// - v_u = max r - min r over l_u (band width about the mean travel line).
// - v_300 = max over all windows [s, s + 300 mm] inside l_u of (max r - min r) in the window.
// - v_2pi = the same for windows of one lead (one revolution of the screw); only evaluated when
//   the lead is given and the samples resolve it (median spacing <= lead / 2).
// - accumulated_1000 = max over all windows [s, s + 1000 mm] inside l_u of (max d - min d): the
//   paper's "1000 mm 内螺距累计误差" (accumulated lead error within any 1000 mm). It uses the raw
//   deviation d, not r: it is the worst travel error between any two grooves up to 1000 mm apart.
// - accumulated_total = max d - min d over l_u: the paper's accumulated lead error of the whole
//   screw (worst travel error between any two grooves of the useful travel).
// Windows: every sample starts one window holding the samples with s <= x <= s + W; the maximum
// over these covers every window of length W (a window that starts between samples holds a subset
// of the samples of one starting at the next sample). If l_u < W, the window is l_u itself.
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "lead/lead.h"
#include "core/window_range.h"

namespace whirl::lead {

struct LeadMetricOptions {
  /// Excess travel l_e excluded at each end of the curve, mm (ISO 3408-3 l_u = l_1 - 2 l_e). >= 0.
  double end_margin_mm = 0.0;
  /// Lead (one revolution of travel) for v_2pi, mm; 0 = not known, v_2pi not evaluated.
  double lead_mm = 0.0;
  /// Window of v_300, mm (ISO 3408-3: 300).
  double window_300_mm = 300.0;
  /// Window of the accumulated error, mm (the paper: 1000).
  double window_1000_mm = 1000.0;
};

struct LeadMetrics {
  double useful_travel_mm = 0;          ///< l_u, mm
  double useful_start_mm = 0;           ///< first position of l_u, mm
  double mean_line_offset_um = 0;       ///< a of the mean travel line at useful_start_mm, um
  double mean_line_slope_um_per_m = 0;  ///< b, um per metre
  double e_a_um = 0;                    ///< mean travel deviation over l_u (signed), um
  double v_u_um = 0;                    ///< band width about the mean travel line over l_u, um
  double v_300_um = 0;                  ///< worst band width within 300 mm, um
  std::optional<double> v_2pi_um;       ///< worst band width within one revolution, um
  double accumulated_1000_um = 0;       ///< worst (max - min) of d within any 1000 mm, um
  double accumulated_total_um = 0;      ///< (max - min) of d over l_u, um
  std::size_t samples = 0;              ///< samples inside l_u
};

/// Computes the metrics above. Throws InputError for an invalid curve (see ValidateLeadDeviation),
/// a negative margin, a margin that leaves fewer than 2 samples, or non-positive windows.
LeadMetrics ComputeLeadMetrics(const LeadDeviation& lead, const LeadMetricOptions& options = {});

/// The end margin's rule: a finite `end_margin_mm` >= 0 that leaves at least 2 samples of the
/// curve in l_u = [x0 + m, x_end - m]. InputError otherwise, naming `name` (the field
/// "end_margin_mm", or the flag that set it), the value in mm, the rule and the travel l_u it
/// leaves. ComputeLeadMetrics checks it with the field's name; a command checks it first with its
/// flag's.
void CheckEndMargin(const LeadDeviation& lead, double end_margin_mm, const std::string& name);

/// Band width over sliding windows (core/window_range.h), used for v_300, v_2pi and the 1000 mm
/// figure.
using whirl::MaxWindowRange;

void to_json(nlohmann::json& j, const LeadMetrics& m);

}  // namespace whirl::lead
