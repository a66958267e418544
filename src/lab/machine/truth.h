#pragma once
// The truth of a simulated machine, for SCORING only (the evaluation's lead deviation of a cut
// and the uncompensated split by source). Training code must not include this header: its
// inputs are measurement records (instruments.h), never these values.
#include <vector>

#include "machine/instruments.h"
#include "machine/timeline.h"

namespace whirl::machine {

struct TruthSample {
  double abs_min = 0;
  double z_mm = 0;
  double head_um = 0;
  double z_um = 0;     ///< Z axis (screw minus bed, or the scale term)
  double extra_um = 0; ///< TimelineOptions::extra_error_um
  /// Along a cut only (TrueCutError): the blank cut at its temperature T_0 at the cut start (the
  /// hall through the blank's lag, FieldMachineConfig::blank_tau_min) and measured at 20 degC,
  /// alpha_blank (T_0 - 20) z (Bryan 1990: only differential expansion
  /// against 20 degC matters; the workpiece simulator's elongation starts from T_0). Without it a
  /// warm hall would show as the Z screw's own growth. 0 from TrueError.
  double blank_um = 0;
  double total_um() const { return head_um + z_um + extra_um + blank_um; }
};

/// m(t, z) at abs_min (linear in time between kept states) and tool position z_mm.
TruthSample TrueError(const MachineTimeline& timeline, double abs_min, double z_mm);
/// m along a cut at every control sample, z = the tool's position.
std::vector<TruthSample> TrueCutError(const MachineTimeline& timeline, const CutRef& cut);
/// The 840D form at abs_min about z_ref_mm: k0 = m(t, z_ref), slope = least-squares slope of
/// m(t, z) over the thread range [z_lo, z_hi] in um per 1000 mm of (z_ref - z).
struct OffsetSlope { double k0_um = 0; double slope_um_per_1000 = 0; };
OffsetSlope TrueOffsetSlope(const MachineTimeline& timeline, double abs_min, double z_ref_mm,
                            double z_lo_mm, double z_hi_mm);
/// The blank's temperature at the cut's start (start ambient of the workpiece simulator: the hall
/// through the blank's lag) and the hall's least-squares slope over the cut, K/h (the blank's
/// ambient drift for the workpiece simulator: the same hall the machine sees).
struct CutHall { double start_c = 20; double slope_k_per_h = 0; };
CutHall HallDuringCut(const MachineTimeline& timeline, const CutRef& cut);

}  // namespace whirl::machine
