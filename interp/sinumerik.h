#pragma once
// SINUMERIK 840D temperature-compensation setting data for one axis (Siemens, SINUMERIK 840D
// Function Manual Extended Functions K3):
//
//   dK = K0 + tan(beta) * (P - P0)                   dK in mm, P actual axis position (MCS), mm
//   SD43900 $SA_TEMP_COMP_ABS_VALUE[axis]   = K0       mm
//   SD43910 $SA_TEMP_COMP_SLOPE[axis]       = tan(beta) dimensionless (mm/mm)
//   SD43920 $SA_TEMP_COMP_REF_POSITION[axis]= P0       mm
//   MD32750 $MA_TEMP_COMP_TYPE = 3 (bit 0: SD43900, bit 1: SD43910/SD43920) must be set (power on).
//   MD32760 $MA_COMP_ADD_VELO_FACTOR caps |tan(beta)| (default 0.01, range 0..0.10).
//
// Time to position (constant axial feed, time origin = start of the cut at the thread start):
//   P(t) = machine_offset_mm + start_position_mm + direction * axial_feed_mm_s * t     (MCS, mm)
// Segment A->B of the breakpoints (interp/breakpoints.h) becomes, with s = +1 (add) or -1
// (subtract),
//   SD43900 = s * l_A / 1000,  SD43910 = s * (l_B - l_A) / 1000 / (P_B - P_A),  SD43920 = P_A
// so that dK(P) = s * l(t(P)) / 1000 on the chord. The segment is active while the axis is between
// P_A and P_B; the plan covers the whole thread: after the curve's last change a final segment with
// slope 0 holds the plateau to the end of the thread.
#include <cstddef>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/limits.h"
#include "core/numbers.h"  // FormatFixed: every value the control reads
#include "fit/arctan_curve.h"
#include "interp/breakpoints.h"
#include "interp/control_requirements.h"

namespace whirl::interp {

/// How the control's dK relates to the predicted elongation l (um, positive = the unmachined
/// section grows, i.e. the cut point moves away from the chuck).
///  kSubtract: dK = -l/1000 mm.  kAdd: dK = +l/1000 mm.
/// The sign is not a free choice: it follows the direction of travel and how the control applies
/// dK (ControlDk). Cutting runs from the free end towards the chuck, so the growth of the
/// unmachined section points against the direction of travel; following the grown material means
/// shifting the axis by -direction * l. If the control adds dK to the position setpoint
/// (ControlDk::kAdded, assumed by default: K3 does not state it plainly), that is
/// s = -direction; if it subtracts dK, s = +direction (ExpectedSign). Check it once on the
/// machine (a constant SD43900 test value and a dial gauge) and record it in the machine profile.
enum class SignConvention { kSubtract, kAdd };
std::string ToString(SignConvention s);                  ///< "subtract" / "add"
SignConvention ParseSignConvention(const std::string&);  ///< InputError for other strings
/// +1 for kAdd, -1 for kSubtract.
double SignFactor(SignConvention s);

/// An axis name in $SA_TEMP_COMP_*[axis] and $AA_IM[axis] (an NC identifier): a letter, then
/// letters, digits or '_', at most kMaxAxisNameLength characters. InputError "<field> = '<axis>':
/// <rule>" otherwise. Every command that writes an axis name checks it here.
inline constexpr std::size_t kMaxAxisNameLength = 32;
void CheckAxisName(const std::string& axis, const std::string& field = "axis");

/// How the control applies the compensation value dK to the axis (a fact of the machine).
enum class ControlDk { kAdded, kSubtracted };
std::string ToString(ControlDk c);                  ///< "added" / "subtracted"
ControlDk ParseControlDk(const std::string& text);  ///< InputError for other strings
/// The only consistent sign: s = -direction if dK is added to the setpoint, +direction otherwise.
SignConvention ExpectedSign(int direction, ControlDk control_dk);

/// Printed resolution of each quantity, identical in the NC program, the PLC table, the plan's
/// HTML and the plan JSON (the plan's values are rounded to it when they are built, so what the
/// files say is exactly what the plan applies): fixed decimals, never an exponent, never "-0".
inline constexpr int kDecimalsPositionMm = 4;    ///< positions, SD43920: 0.1 um
inline constexpr int kDecimalsSd43900Mm = 6;     ///< SD43900: 1 nm (below any control's resolution)
inline constexpr int kDecimalsSd43910 = 8;       ///< SD43910: 1e-8 = 0.01 um per metre of travel
inline constexpr int kDecimalsTimeS = 3;         ///< times: 1 ms
inline constexpr int kDecimalsElongationUm = 3;  ///< predicted elongation: 1 nm
/// x rounded to `decimals` decimals (the value FormatFixed, core/numbers.h, prints).
double RoundTo(double x, int decimals);

/// MD32760 bounds from K3.
inline constexpr double kMd32760Default = 0.01;
inline constexpr double kMd32760Max = 0.10;

/// SETAL numbers whirl raises lie within the user cycle alarms 65000..69999; 60000..64999 belong
/// to Siemens' own cycles (SINUMERIK 840D cycle alarm ranges; recalled, not confirmed against a
/// copy of Siemens' Diagnostics Manual here).
/// Whether a cycle alarm stops the program depends on its number's sub-range (and the machine's
/// alarm configuration). Recalled, not confirmed here: 65000..65999 stop the interpreter (cleared
/// with RESET), 66000..66999 stop it (cleared with NC START), 67000..67999 are only displayed and
/// the program goes on. The programs do not depend on it: after every SETAL they jump to their
/// end (kProgramEndLabel), so nothing is cancelled, saved or written after a failed check,
/// whatever the alarm's response. What the response still decides: if the alarm does not stop
/// the program, the calling part program goes on and cuts without whirl's compensation (the
/// control as found). So keep whirl's alarms in a stopping sub-range (the default numbering,
/// 65000..65004, lies in 65000..65999) and check once on the machine that the start alarm stops.
inline constexpr int kUserAlarmFirst = 65000;
inline constexpr int kUserAlarmLast = 69999;
/// The default numbering: the drift check's four alarms from 65000 (drift_missing_alarm,
/// drift_action.h), then the plan's start alarm.
inline constexpr int kDefaultStartAlarm = kUserAlarmFirst + 4;
/// The label just before M17 that every failed check of whirl's programs jumps to (GOTOF).
inline constexpr const char* kProgramEndLabel = "WHIRL_END";
/// Part-program lines of a check: go on at `ok_label` if `condition` holds (a single-block
/// conditional jump, "IF <condition> GOTOF <ok_label>"), else raise SETAL(alarm) and jump to
/// kProgramEndLabel. No jump leaves or enters an IF block (whether a control accepts a jump out
/// of IF..ENDIF is not checked here, so the checks do without one).
std::string CheckOrAlarm(const std::string& condition, int alarm, const std::string& ok_label);
/// Largest |position| accepted for the machine offset, the thread start and other axis positions,
/// mm: 100 m, longer than any machine bed (a larger value is a typing error, and at 1e308 the
/// trigger positions of neighbouring segments become equal).
inline constexpr double kMaxPositionMm = kMaxAxisPositionMm;  // core/limits.h

/// SINUMERIK program names: two letters, then letters, digits or '_', at most 24 characters
/// (Siemens, SINUMERIK 840D sl Programming Manual Fundamentals, "Program names": the first two
/// characters must be letters, then only letters, digits and underscores, no blanks or other
/// separators, the '.' only before the file extension, at most 24 characters; recalled, not
/// checked against a copy of the manual here: the stricter reading is used). The program names
/// whirl writes into its headers are those of the files (their stem, the extension .SPF aside).
inline constexpr std::size_t kMaxProgramNameLength = 24;
/// InputError naming `what` (e.g. "--nc 'x/1 my comp.spf'") and the rule unless `name` is a
/// SINUMERIK program name (see kMaxProgramNameLength).
void CheckProgramName(const std::string& name, const std::string& what);
/// The program name of an NC file: the file name without its extension, checked by
/// CheckProgramName (`flag` names the option in the message).
std::string ProgramNameOf(const std::string& path, const std::string& flag);
/// InputError if a program and its reset program would be one program on the control: the same
/// name ignoring case (a case-insensitive file system, such as that of a Windows-based HMI,
/// stores A.SPF and a.spf as one file), which also covers one file given twice (./A.SPF, A.SPF).
void CheckDistinctProgramNames(const std::string& program, const std::string& reset_program);

struct PlanOptions {
  /// Largest |applied compensation - predicted curve| along the thread, um, in
  /// kPlanToleranceRange of core/limits.h (1 nm to 10 mm).
  double tolerance_um = 0.5;
  /// Axis name used in $SA_TEMP_COMP_*[axis] and $AA_IM[axis] (letters, digits, '_').
  std::string axis = "Z";
  /// Axis position at the thread start (time 0), in the coordinate system of the part program, mm.
  double start_position_mm = 0;
  /// Direction of travel along the axis while cutting: +1 or -1.
  int direction = 1;
  /// Machine coordinate of the program's zero for this axis, mm (SD43920 and $AA_IM are MCS).
  double machine_offset_mm = 0;
  /// dK = s * l / 1000 (see SignConvention); must equal ExpectedSign(direction, control_dk).
  SignConvention sign = SignConvention::kSubtract;
  /// How the control applies dK (machine profile field "control_dk").
  ControlDk control_dk = ControlDk::kAdded;
  /// MD32760 $MA_COMP_ADD_VELO_FACTOR: cap on |SD43910| (0 < cap <= 0.10). A larger slope is an
  /// InputError naming the segment, its slope and the cap.
  double md32760 = kMd32760Default;
  /// Check-grid step for the tolerance, s (BreakpointOptions::check_step_s).
  double check_step_s = 0.25;
  /// Synchronized-action IDs whirl may use, [sync_id_first, sync_id_last] within 1..255: one per
  /// segment (the first segment's too, at the thread start) plus one for the restore at the
  /// thread end. The NC program cancels exactly these IDs before it starts, so they are the ones
  /// the machine builder reserved for whirl (machine profile, or explicit flags when there is
  /// none). 0 and 0: not set, the default; a plan can be built, but FormatNcProgram and
  /// FormatNcResetProgram refuse (there is no safe default range).
  int sync_id_first = 0;
  int sync_id_last = 0;
  /// SETAL number the NC program raises, before it changes anything, when it is called with the
  /// axis at or past the thread start (its first position trigger): the cut must start with the
  /// axis before the thread start (no resume from mid-thread). Within kUserAlarmFirst..
  /// kUserAlarmLast; profile key "start_alarm"; default kDefaultStartAlarm.
  int start_alarm = kDefaultStartAlarm;
  /// R parameters R<n>..R<n+3> the NC program uses to save the setting data it found (SD43900,
  /// SD43910, SD43920) and a marker (1 while whirl's compensation is active), so the thread end
  /// and the reset program restore exactly what was there before. 0..9996; the machine must
  /// have them (MD28050 $MC_MM_NUM_R_PARAM). They are the user's R parameters, so they come
  /// only from the machine profile (save_r_first) or an explicit flag without one: -1, the
  /// default, is "not set": a plan can be built, but FormatNcProgram and FormatNcResetProgram
  /// refuse when the plan saves anything (not when it hands its slope to the drift action).
  int save_r_first = -1;
  /// -1: the plan writes SD43900 itself. >= 0: combined with the live drift action
  /// (interp/drift_action.h): the plan writes its K0 into $AC_PARAM[workpiece_k0_param], which the
  /// drift action adds to the machine's K0, so SD43900 has one writer.
  int workpiece_k0_param = -1;
  /// -1: the plan writes SD43910/SD43920 itself. >= 0 (only with workpiece_k0_param): the drift
  /// action also owns the slope (it adds the machine's Z-screw slope, drift_action.h): the plan
  /// writes its SD43910 into $AC_PARAM[workpiece_slope_param] and its SD43920 into
  /// $AC_PARAM[workpiece_slope_param + 1], saves nothing, uses no R marker and resets its slots
  /// to 0 at the thread end.
  int workpiece_slope_param = -1;
  /// -1: no blank latch. >= 0 (only with workpiece_slope_param): the drift action runs the grey
  /// box's blank estimate B in $AC_PARAM[blank_param] (drift_action.h); the plan's first segment
  /// copies it into $AC_PARAM[blank_param + 1] at the thread start (the latch the drift action's
  /// slope reads for the whole cut) and the thread end, the undo of an aborted run and the reset
  /// program write 20 there (no blank term). The plan then accepts the drift action in mode 2 or
  /// 3; without it, mode 3 (an action that reads a latch) is refused.
  int blank_param = -1;
  /// The drift action's liveness slot (the profile's drift.param_first; -1: the machine has no
  /// drift action): the running action writes its mode there every interpolation cycle (1 owns
  /// SD43900, 2 owns SD43900-43920). The plan clears the slot, dwells 0.1 s and reads it back, so
  /// the check sees the action run now (a marker in a retentive R parameter would outlive the
  /// actions at power on). It expects 0 when the plan writes the setting data itself, 1 when only
  /// K0 is handed over and 2 when the slope is handed over too, and otherwise raises
  /// drift_missing_alarm (expected 1 or 2, found 0: the action is not running), + 1 (expected 0:
  /// a running drift action would be a second writer) or + 2 (the action's mode does not match).
  int drift_alive_param = -1;
  int drift_missing_alarm = kUserAlarmFirst;

  /// InputError naming the field, value and rule for any option out of range (positions within
  /// +-kMaxPositionMm, alarms within the user cycle alarms and distinct), and for a sign that is
  /// not ExpectedSign(direction, control_dk).
  void Validate() const;
  /// True when the synchronized-action IDs are set (sync_id_first > 0).
  bool HasSyncIds() const { return sync_id_first > 0; }
  /// True when the R parameters are set (save_r_first >= 0).
  bool HasSaveR() const { return save_r_first >= 0; }
};

struct CompensationSegment {
  double t_a_s = 0, t_b_s = 0;    ///< segment start/end time from the start of the cut, s
  double p_a_mm = 0, p_b_mm = 0;  ///< axis positions (MCS) at t_a and t_b, mm
  double l_a_um = 0, l_b_um = 0;  ///< predicted elongation at t_a and t_b, um
  double sd43900_mm = 0;          ///< $SA_TEMP_COMP_ABS_VALUE = s * l_a / 1000, mm
  double sd43910 = 0;             ///< $SA_TEMP_COMP_SLOPE = s (l_b - l_a)/1000/(p_b - p_a), -
  double sd43920_mm = 0;          ///< $SA_TEMP_COMP_REF_POSITION = p_a, mm
};

struct CompensationPlan {
  PlanOptions options;
  double axial_feed_mm_s = 0;                 ///< constant axial feed, mm/s
  double thread_length_mm = 0;                ///< threaded length, mm
  double cutting_time_s = 0;                  ///< thread_length / feed, s
  std::vector<CompensationSegment> segments;  ///< in order of travel, contiguous
  std::size_t point_count = 0;                ///< breakpoints = segments + 1
  std::size_t uniform_point_count = 0;  ///< uniform points needed for the same bound (0: > 1e6)
  double max_deviation_um = 0;          ///< largest |chord - curve| on the check grid, um
  double effective_tolerance_um = 0;    ///< tolerance minus the curvature margin, um
  double max_abs_slope = 0;             ///< max |SD43910|
};

/// Axis position (MCS, mm) at time t_s under the plan's options and feed.
double AxisPositionMm(const PlanOptions& options, double axial_feed_mm_s, double t_s);

/// Builds the plan for a curve l(t) (um) over the cutting time thread_length_mm / axial_feed_mm_s.
/// `forced_times_s` are kinks that must be breakpoints. Throws InputError for invalid options,
/// non-positive or non-finite feed or length, and any |SD43910| > md32760.
CompensationPlan BuildPlan(const CurveFunction& curve_um, double axial_feed_mm_s,
                           double thread_length_mm, const PlanOptions& options,
                           const std::vector<double>& forced_times_s = {});
/// The arctan curve: its settle time is a forced breakpoint, so the plateau is one segment with
/// slope 0 to the end of the thread.
CompensationPlan BuildPlan(const fit::ArctanCurve& curve, double axial_feed_mm_s,
                           double thread_length_mm, const PlanOptions& options);

/// The elongation (um) the plan compensates with the axis at `axis_position_mm` (MCS),
/// reconstructed from SD43900/SD43910/SD43920 and the sign convention only: the active segment is
/// the last one whose SD43920 the axis has passed in the direction of travel; value = (SD43900 +
/// SD43910 (P - SD43920)) * 1000 / s. Before the thread start it is 0: the NC program writes the
/// first segment only when the axis reaches the thread start, until then the control applies what
/// it applied before the call. Positive = the same direction as the elongation it cancels.
double AppliedCompensationUm(const CompensationPlan& plan, double axis_position_mm);

/// Checks a plan read back or built elsewhere: contiguous segments, finite values, slopes within
/// the cap. InputError naming the segment and the rule.
void ValidatePlan(const CompensationPlan& plan);

// --- Writers -------------------------------------------------------------------------------

/// JSON of the plan (schema "whirl.plan", version 2: settings gained control_dk, the
/// synchronized-action ID range and the R parameters): settings, segments with units, counts.
/// Callers add "curve" and "prediction" objects beside it.
void to_json(nlohmann::json& j, const CompensationPlan& plan);
void from_json(const nlohmann::json& j, CompensationPlan& plan);
void to_json(nlohmann::json& j, const PlanOptions& options);
void from_json(const nlohmann::json& j, PlanOptions& options);

/// CSV table for a PLC that writes the setting data (one row per segment, in order):
/// segment,trigger_position_mm,t_a_s,t_b_s,p_a_mm,p_b_mm,l_a_um,l_b_um,sd43900_mm,sd43910,
/// sd43920_mm, fixed decimals per quantity (kDecimals*), then one final row "restore" at the
/// thread end whose setting-data cells say "saved" (write back the values found before the cut),
/// with '#' comment lines (axis, sign, direction, MD32760, tolerance, the start condition and its
/// alarm, provenance).
std::string FormatPlcCsv(const CompensationPlan& plan,
                         const std::vector<std::string>& provenance = {});

/// The compensation points for a report: time_s,thread_position_mm,elongation_um,sd43900_mm,
/// sd43910,sd43920_mm, one row per breakpoint with the setting data of the segment that starts
/// there, fixed decimals per quantity (kDecimals*); the last breakpoint (thread end) restores the
/// values found before the cut, so its setting-data cells read "saved", never a 0 that reads as
/// "set it to 0". Comment lines ('#') first.
std::string FormatPointsCsv(const CompensationPlan& plan, const std::vector<std::string>& comments);

/// Text facts for the NC program header.
struct NcProgramInfo {
  /// The program's own name and that of its reset program, as on the control (the files' stems,
  /// ProgramNameOf); checked by CheckProgramName and CheckDistinctProgramNames.
  std::string program_name = "WHIRL_TEMP_COMP";
  std::string reset_program_name = "WHIRL_TEMP_COMP_RESET";
  std::string curve_source;  ///< e.g. "model m.json, screw s.json (L=..., t_s=..., k=...)";
                             ///< control characters become spaces (one comment line)
};

/// SINUMERIK subprogram (.SPF) that leaves the control as it found it:
///   STOPRE; IF $AA_IM[<axis>]<P_start GOTOF <ok> ('>' travelling in -direction), else
///     SETAL(start_alarm) and GOTOF WHIRL_END (CheckOrAlarm), before anything is changed: every
///     action below is triggered by the position alone, so with the axis at or past a trigger it
///     would fire at once (a WHEN whose condition holds fires in the first interpolation cycle).
///     The cut starts with the axis before the thread start; there is no resume from mid-thread;
///   [with a drift action on the machine: its liveness check, alarms drift_missing_alarm + 0..2,
///     each followed by the jump to WHIRL_END likewise];
///   CANCEL(n) for every ID of [sync_id_first, sync_id_last] (stale actions of an aborted run);
///   STOPRE; IF R<m+3>==1 (an earlier run never reached its restore: an aborted cut, a power
///     failure mid-cut): write back the values it saved in R<m>..R<m+2>, slope first, and clear
///     the marker, as the reset program does, so the approach applies what the control had before
///     that run (combined: the plan's K0 slot returns to 0 unconditionally; with the slope handed
///     over there is no marker and only its K0 and slope slots are set to 0);
///   IF R<m+3><>1: save SD43900/43910/43920 into R<m>..R<m+2> (m = save_r_first), set the marker
///     R<m+3>=1;
///   ID=<id> WHEN $AA_IM[<axis>]>=<P_A> DO $$SA_TEMP_COMP_ABS_VALUE[<axis>]=...
///        $$SA_TEMP_COMP_SLOPE[<axis>]=... $$SA_TEMP_COMP_REF_POSITION[<axis>]=...
///     one modal action per segment, the first at the thread start, so nothing of the plan is
///     applied during the approach (the control keeps what it applied before the call), IDs
///     counting up from sync_id_first;
///   ID=<last> WHEN $AA_IM[<axis>]>=<thread end> DO <restore from R<m>..R<m+2>> $R<m+3>=0;
///   WHIRL_END: M17 (subprogram end). Call it before the cutting block. IDs or R parameters not
///   set, or more IDs needed than the range holds, are an InputError (raise the tolerance or
///   widen the range). Header
///   comments state the program names, MD32750 = 3, the MD32760 cap against the largest slope,
///   the sign rule, the axis, the start condition and its alarm, IDs, R parameters and the
///   control's limits it depends on (MD28250 for its actions, MD28254 for the $AC_PARAM it uses).
/// Not verified on a control here (docs/840d.md): the access level for main-run writes of
/// SD43900-43920 on a given machine.
std::string FormatNcProgram(const CompensationPlan& plan, const NcProgramInfo& info = {});

/// The reset subprogram for an aborted cut: CANCEL(n) over the ID range, then, if the marker
/// R<m+3> is 1, write back the saved SD43900/43910/43920 and clear the marker; M17. InputError if
/// the IDs or (unless the slope is handed over) the R parameters are not set.
std::string FormatNcResetProgram(const PlanOptions& options, const NcProgramInfo& info = {});

/// What the control must provide for the plan's program (control_requirements.h), the same
/// thresholds its header states: MD32750 bits 0 and 1 on the axis, MD32760 >= the largest
/// |SD43910|, MD28250 room for its synchronized actions (one per segment and the restore) and,
/// when it uses $AC_PARAM (the drift action's liveness slot, the hand-over slots), MD28254 >=
/// the largest index + 1. `program` names the program in the uses.
std::vector<ControlRequirement> PlanRequirements(const CompensationPlan& plan,
                                                 const std::string& program);

}  // namespace whirl::interp
