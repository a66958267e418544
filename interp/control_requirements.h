#pragma once
// What the control must provide for whirl's programs: one machine datum each, with the rule its
// value must meet, built from the plan and the drift action's data (sinumerik.h
// PlanRequirements, drift_action.h DriftRequirements) rather than read back from the programs'
// text. The programs' headers state the same thresholds ("; requires ..."; a test checks that
// they agree). When one control runs several programs at once (the workpiece plan and the live
// drift action), MergeRequirements lists each datum once, with the rule both programs need
// together:
//   MD10300 $MN_FASTIO_ANA_NUM_INPUTS   analog inputs: the largest $A_INA index read (the max);
//   MD28250 $MC_MM_NUM_SYNC_ELEMENTS    synchronized actions active at once: the sum (the plan's
//                                       ID actions and the drift action's static IDS actions run
//                                       together);
//   MD28254 $MC_MM_NUM_AC_PARAM         $AC_PARAM slots: the largest index + 1 (the max; the
//                                       plan hands its values over through slots the drift
//                                       action reads);
//   MD32750 $MA_TEMP_COMP_TYPE          per axis, the bits that must be set (bit 0 SD43900,
//                                       bit 1 SD43910/SD43920: the union);
//   MD32760 $MA_COMP_ADD_VELO_FACTOR    per axis, the largest |SD43910| written (the sum: the
//                                       drift action writes S_w + S_m).
// Siemens, SINUMERIK 840D sl Function Manual Extended Functions, K3 (temperature compensation),
// and Synchronized Actions (MD28250, MD28254); the analog inputs: A4 (NCK I/O).
#include <limits>
#include <string>
#include <vector>

namespace whirl::interp {

enum class RequirementRule {
  kAtLeast,  ///< the control's value >= `value`
  kBits,     ///< the bits of `value` (an integer bit mask) set in the control's value
};
/// How the needs of two programs on one control combine.
enum class RequirementMerge { kMax, kSum, kUnion };

struct ControlRequirement {
  std::string datum;  ///< e.g. "MD28254 $MC_MM_NUM_AC_PARAM"
  std::string axis;   ///< the axis of an axis machine datum (MD32750, MD32760); "" otherwise
  RequirementRule rule = RequirementRule::kAtLeast;
  RequirementMerge merge = RequirementMerge::kMax;
  double value = 0;  ///< the threshold (kAtLeast) or the bit mask (kBits)
  int decimals = 0;  ///< decimals of the threshold as written (e.g. SD43910's 8)
  /// The machine profile's value of the datum; NaN: the profile does not state it.
  double stated = std::numeric_limits<double>::quiet_NaN();
  /// What needs it, one phrase per program (e.g. "$AC_PARAM up to index 115 (WHIRL_DRIFT_COMP)").
  std::vector<std::string> uses;
};

/// A requirement with one use.
ControlRequirement MakeRequirement(const std::string& datum, const std::string& axis,
                                   RequirementRule rule, RequirementMerge merge, double value,
                                   int decimals, const std::string& use);

/// One sentence, e.g. "MD28254 $MC_MM_NUM_AC_PARAM >= 116: $AC_PARAM up to index 115
/// (WHIRL_DRIFT_COMP) (profile: 300)" or "MD32750 $MA_TEMP_COMP_TYPE on axis Z: bits 0 and 1
/// set (= 3): ...".
std::string ToString(const ControlRequirement& r);

/// The requirements of two programs run together: each (datum, axis) once, combined by its
/// `merge` (see the header comment), in the order of first appearance; the uses of both kept.
std::vector<ControlRequirement> MergeRequirements(const std::vector<ControlRequirement>& a,
                                                  const std::vector<ControlRequirement>& b);

}  // namespace whirl::interp
