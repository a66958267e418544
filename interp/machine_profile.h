#pragma once
// A machine profile: the facts of one SINUMERIK 840D whirling machine that every compensation
// program for it needs, kept in one file so they are stated once and never silently defaulted.
//
//   {"schema": "whirl.machine", "schema_version": 2,
//    "name": "WM-1 whirling machine (example values)",
//    "axis": "Z",                 compensated axis (letters, digits, '_')
//    "direction": 1,              direction of travel while cutting: +1 or -1
//    "machine_offset_mm": -812.5, machine coordinate (MCS) of the program zero on that axis, mm,
//                                 within +-1e5 mm
//    "start_position_mm": 0,      optional: axis position of the thread start in program
//                                 coordinates, mm (else required per job: --start-position-mm)
//    "control_dk": "added",       how the control applies dK: "added" to the position setpoint
//                                 (assumed by Siemens' K3 description) or "subtracted"; verify
//                                 once with a constant SD43900 test value and a dial gauge
//    "md32760": 0.01,             MD32760 $MA_COMP_ADD_VELO_FACTOR of the axis (cap on |SD43910|)
//    "sync_id_first": 200, "sync_id_last": 255,
//                                 synchronized-action IDs reserved for whirl (1..255); the
//                                 programs cancel exactly this range first; at least 2
//    "save_r_first": 90,          R<n>..R<n+3> hold the setting data found before a cut and a
//                                 marker (MD28050 must provide them); required: the R
//                                 parameters are the user's, there is no default
//    "start_alarm": 65004,        SETAL number of the plan called with the axis at or past the
//                                 thread start (65000..69999, the user cycle alarms; after
//                                 every alarm the programs jump to their end, so they change
//                                 nothing whatever its response; recalled, not confirmed here:
//                                 65000..66999 stop the program, 67000..67999 are only
//                                 displayed, and then the calling program cuts without
//                                 whirl's compensation: see sinumerik.h kUserAlarmFirst)
//    "control": {                 the control's own limits (machine data), checked and named in
//                                 the programs' headers as prerequisites:
//      "md10300_analog_inputs": 8,    MD10300 $MN_FASTIO_ANA_NUM_INPUTS: NCK analog inputs
//                                     (0..999); every $A_INA index is at most this
//      "md28250_sync_elements": 400,  MD28250 $MC_MM_NUM_SYNC_ELEMENTS: elements for synchronized
//                                     actions (>= 1); at least one per action of whirl's ranges
//      "md28254_ac_params": 200},     MD28254 $MC_MM_NUM_AC_PARAM: $AC_PARAM[0..n-1] exist
//                                     (1..10000); every slot whirl uses is below it
//    "drift": {                   optional: the live machine-drift action (interp/drift_action.h)
//      "sync_id_first": 150, "sync_id_last": 190,  its IDS range, above the plan's; at least 2
//      "param_first": 100, "param_last": 180,
//                                 the $AC_PARAM slots it may use (at least 4), disjoint from the
//                                 plan's slots below
//      "save_r_first": 80,        R<n>..R<n+4>: setting data found, markers; disjoint from the
//                                 plan's R
//      "ipo_cycle_ms": 4.0,       interpolation cycle [ms], 0.1..100
//      "error_direction": 1,      +1: the model's error is the tool's displacement along +axis
//      "workpiece_k0_param": 99,  $AC_PARAM the whirling plan writes its K0 into when combined
//      "workpiece_slope_param": 97, optional: the plan also hands its SD43910 (97) and SD43920
//                                 (98) to the drift action, which then owns all three
//      "blank_param": 95,         optional (needs workpiece_slope_param): the grey box's blank
//                                 estimate B (95, the drift action writes it) and its value
//                                 latched at the cut start (96, the plan writes it)
//      "slope": {"fixed_end_position_mm": 5587.5, "growth_direction": -1},
//                                 optional: the machine's slope model (drift nc --slope-model):
//                                 MCS position of the zero of the growth (a feed screw's fixed
//                                 bearing) and +1/-1 if the distance from it grows towards +/-axis
//      "missing_alarm": 65000,    first of four SETAL numbers (65000..69996): a combined plan
//                                 without the action running, a plan writing the data itself
//                                 beside it, a mode mismatch, a drift program finding a plan's
//                                 compensation active; none of them the start_alarm
//      "analog_inputs": {"t3_C": {"index": 3, "scale": 0.1, "offset": 0.0}, ...}}}
//                                 T = scale * $A_INA[index] + offset [degC] per model input;
//                                 index 1..MD10300, 1e-6 <= |scale| <= 1e3, |offset| <= 1e4
//
// Schema version 1 (no "control", "start_alarm" or "drift.param_last") still loads, with these
// documented defaults: the control's limits are not stated (not checked; the headers still name
// what each program needs), start_alarm = drift.missing_alarm + 4 (65004 without a drift object),
// drift.param_last = the slot below the lowest workpiece slot above param_first (9999 if none).
//
// One validation (MachineProfile::Validate, run by LoadMachineProfile and by every use of a
// profile) checks each value and the sections against each other, so a profile one command
// accepts is accepted by every command; what depends on a model or a plan (how many IDs and
// $AC_PARAM slots it takes) is checked when its program is written, against these ranges.
// The plan's sign follows from direction and control_dk (interp/sinumerik.h ExpectedSign).
#include <filesystem>
#include <optional>
#include <string>

#include "interp/drift_action.h"
#include "interp/sinumerik.h"

namespace whirl::interp {

struct MachineProfile {
  static constexpr const char* kSchema = "whirl.machine";
  static constexpr int kSchemaVersion = 2;
  int schema_version = kSchemaVersion;  ///< as read (1: the documented defaults above)
  std::string name;
  std::string axis = "Z";
  int direction = 1;
  double machine_offset_mm = 0;
  std::optional<double> start_position_mm;
  ControlDk control_dk = ControlDk::kAdded;
  double md32760 = kMd32760Default;
  int sync_id_first = 0;  ///< required in the file
  int sync_id_last = 0;
  int save_r_first = -1;  ///< required in the file
  int start_alarm = kDefaultStartAlarm;
  ControlLimits control;                    ///< the "control" object (version 1: not stated)
  std::optional<DriftActionOptions> drift;  ///< the "drift" object, when present

  /// The whole profile checked (see the header comment): InputError naming the file, the key, the
  /// value and the rule.
  void Validate() const;
  /// Copies the machine's facts into plan options (tolerance and check step are left alone), sets
  /// the sign to ExpectedSign(direction, control_dk) and, when the profile has a drift action, its
  /// liveness slot and alarm (a plan that writes the setting data itself refuses beside it).
  /// Validates the profile first.
  void ApplyTo(PlanOptions& options) const;
  /// The plan combined with the drift action: its K0 goes to drift.workpiece_k0_param (and its
  /// slope and reference to drift.workpiece_slope_param, +1, when the profile has it) and it
  /// requires the drift action to run in the matching mode. InputError naming the file if
  /// "drift" is missing.
  void ApplyCombinedTo(PlanOptions& options) const;
  /// The drift action's options (axis, control_dk and the control's limits from the profile).
  /// InputError if absent. Validates the profile first.
  DriftActionOptions DriftOptions() const;
  /// True while the name still says "illustrative values" (the shipped example_840d.json, copied
  /// and not yet made the user's): plan and drift nc warn that its values are not a machine's.
  bool Illustrative() const;
  std::string source;  ///< file name, for messages

 private:
  void Fill(PlanOptions& options) const;  // ApplyTo without the validation
  DriftActionOptions FillDrift() const;   // DriftOptions without the validation
};

/// Reads and validates a profile: unknown keys, missing required keys, wrong types and values out
/// of range are InputErrors naming the file, the key, the value and the rule.
MachineProfile LoadMachineProfile(const std::filesystem::path& path);

}  // namespace whirl::interp
