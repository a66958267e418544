#pragma once
// A machine profile: the facts of one SINUMERIK 840D whirling machine that every compensation
// program for it needs, kept in one file so they are stated once and never silently defaulted.
//
//   {"schema": "whirl.machine", "schema_version": 1,
//    "name": "WM-1 whirling machine (example values)",
//    "axis": "Z",                 compensated axis (letters, digits, '_')
//    "direction": 1,              direction of travel while cutting: +1 or -1
//    "machine_offset_mm": -812.5, machine coordinate (MCS) of the program zero on that axis, mm
//    "start_position_mm": 0,      optional: axis position of the thread start in program
//                                 coordinates, mm (else required per job: --start-position-mm)
//    "control_dk": "added",       how the control applies dK: "added" to the position setpoint
//                                 (assumed by Siemens' K3 description) or "subtracted"; verify
//                                 once with a constant SD43900 test value and a dial gauge
//    "md32760": 0.01,             MD32760 $MA_COMP_ADD_VELO_FACTOR of the axis (cap on |SD43910|)
//    "sync_id_first": 200, "sync_id_last": 255,
//                                 synchronized-action IDs reserved for whirl (1..255); the
//                                 programs cancel exactly this range first
//    "save_r_first": 90,          R<n>..R<n+3> hold the setting data found before a cut and a
//                                 marker (MD28050 must provide them)
//    "drift": {                   optional: the live machine-drift action (interp/drift_action.h)
//      "sync_id_first": 150, "sync_id_last": 190,  its IDS range, disjoint from the plan's
//      "param_first": 100,        first $AC_PARAM slot it uses
//      "save_r_first": 80,        R<n>..R<n+4>: setting data found, markers; disjoint from the
//                                 plan's R
//      "ipo_cycle_ms": 4.0,       interpolation cycle [ms]
//      "error_direction": 1,      +1: the model's error is the tool's displacement along +axis
//      "workpiece_k0_param": 99,  $AC_PARAM the whirling plan writes its K0 into when combined
//      "workpiece_slope_param": 97, optional: the plan also hands its SD43910 (97) and SD43920
//                                 (98) to the drift action, which then owns all three
//      "slope": {"fixed_end_position_mm": 5587.5, "growth_direction": -1},
//                                 optional: the machine's slope model (drift nc --slope-model):
//                                 MCS position of the zero of the growth (a feed screw's fixed
//                                 bearing) and +1/-1 if the distance from it grows towards +/-axis
//      "missing_alarm": 65000,    first of four SETAL numbers: a combined plan without the action
//                                 running, a plan writing the data itself beside it, a mode
//                                 mismatch, a drift program finding a plan's compensation active
//      "analog_inputs": {"t3_C": {"index": 3, "scale": 0.1, "offset": 0.0}, ...}}}
//                                 T = scale * $A_INA[index] + offset [degC] per model input
//
// The plan's sign follows from direction and control_dk (interp/sinumerik.h ExpectedSign).
#include <filesystem>
#include <optional>
#include <string>

#include "interp/drift_action.h"
#include "interp/sinumerik.h"

namespace whirl::interp {

struct MachineProfile {
  static constexpr const char* kSchema = "whirl.machine";
  static constexpr int kSchemaVersion = 1;
  std::string name;
  std::string axis = "Z";
  int direction = 1;
  double machine_offset_mm = 0;
  std::optional<double> start_position_mm;
  ControlDk control_dk = ControlDk::kAdded;
  double md32760 = kMd32760Default;
  int sync_id_first = 1;
  int sync_id_last = 255;
  int save_r_first = 90;
  std::optional<DriftActionOptions> drift;  ///< the "drift" object, when present

  /// Copies the machine's facts into plan options (tolerance and check step are left alone), sets
  /// the sign to ExpectedSign(direction, control_dk) and, when the profile has a drift action, its
  /// liveness slot and alarm (a plan that writes the setting data itself refuses beside it).
  void ApplyTo(PlanOptions& options) const;
  /// The plan combined with the drift action: its K0 goes to drift.workpiece_k0_param (and its
  /// slope and reference to drift.workpiece_slope_param, +1, when the profile has it) and it
  /// requires the drift action to run in the matching mode. InputError naming the file if
  /// "drift" is missing.
  void ApplyCombinedTo(PlanOptions& options) const;
  /// The drift action's options (axis and control_dk from the profile). InputError if absent.
  DriftActionOptions DriftOptions() const;
  std::string source;  ///< file name, for messages
};

/// Reads and validates a profile: unknown keys, missing required keys, wrong types and values out
/// of range are InputErrors naming the file, the key, the value and the rule.
MachineProfile LoadMachineProfile(const std::filesystem::path& path);

}  // namespace whirl::interp
