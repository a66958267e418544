#pragma once
// The live machine-drift compensation on a SINUMERIK 840D: a drift model (src/product/drift, kinds
// mlr and dynamic) evaluated every interpolation cycle by static synchronized actions from the
// machine's analog inputs, written into SD43900 $SA_TEMP_COMP_ABS_VALUE (the position-independent
// K0 that Siemens designed for exactly this, Siemens K3), plus the same model as a PLC table.
//
// Inputs. Sensor i of the model reads T_i = scale_i * $A_INA[index_i] + offset_i [degC]; an extra
// input (e.g. spindle_rpm) reads scale * $A_INA[index] + offset in its own unit. The mapping is a
// machine fact (profile "drift.analog_inputs", or --input on the command line).
// Rises. u_i = T_i - T_ref,i: T_ref is the model's reference_C (reference "model", for a control
// that runs all day) or the temperatures when the action starts (reference "start", Miao et al.'s
// convention of rises from the run's first row).
// Lags. Each lagged feature runs the recursion of drift/regression.h FirstOrderLag once per
// interpolation cycle T_ipo: L <- L + a (u - L), a = 1 - exp(-T_ipo / tau), L_0 = u_0.
// Elapsed time (drift/model.h: the warm-up terms of drift fit's time1, time2 and sensors+time
// candidates). The control counts it itself, from the cycle the actions start (flag 0): each
// elapsed-time feature is the lag of a unit step, x <- x + a (1 - x), x = 0 in the start's cycle,
// so x = 1 - exp(-t / tau) with t the time since the program's start; no analog input, no
// system timer. Run the program when the machine starts as the model's training runs did (the
// model's t0); after the longest training run x goes on towards 1, so the warm-up approaches its
// plateau b0 + sum A_j and never passes it (the gains share one sign, drift/regression.h).
// Output. dK = s * e / 1000 mm with e = b0 + sum_f b_f x_f [um] (drift/model.h), where
// s = -error_direction if the control adds dK to the setpoint and +error_direction if it
// subtracts it; error_direction = +1 means the model's error is the tool's displacement along
// +axis relative to the workpiece (what a dial gauge on the table reads along +axis).
//
// $AC_PARAM layout from param_first: the liveness slot (the last action writes the mode there
// every cycle: 1 owns SD43900, 2 owns SD43900-43920, 3 also reads the blank latch; the plans
// clear it, dwell and read it back, sinumerik.h), then one slot per model feature (input-major,
// as DriftModel::features), one reference slot per sensor (reference "start") and an init flag,
// and for a model of more than 8 features a slot its sum is accumulated in, 8 terms per action
// (every program line must stay within the control's 512 characters); with a slope model its
// slots follow likewise, then S_m; with a blank term the init flag of B (B itself and its latch
// are the profile's blank_param, + 1).
// The machine must provide them (MD28254 $MC_MM_NUM_AC_PARAM).
// A mixed line (DriftComponent, e.g. the grey box with weight w and a sensor-free rule with
// 1 - w) has, after the liveness slot, per component its offset model's slots, its slope
// model's and its S_j, and its K_j (the offset's partial-sum slot where it has one), then the
// program's S_m = sum_j w_j S_j, then the blank's flag; each component's actions run as for one
// model, its K_j summed into its own slot, then S_m, then the output with K_m = sum_j w_j K_j.
// Action order (IDs count up from sync_id_first; actions run in ID order every cycle):
//   [start: capture T_ref once] -> rises u -> [elapsed updates] -> [once: L = u, x = 0, flag]
//   -> [lag updates] -> [partial sums] -> [slope model likewise, B's init and lag, S_m]
//   -> SD43900 (-43920).
// Each bracket's assignments of all inputs share actions, as many per action as the line holds
// (a DO part holds several actions: Siemens, SINUMERIK 840D sl Synchronized Actions function
// manual; none of them reads another of the same step), so the IDS count grows with the line
// length of the model, not with one action per input: the field's every-sensor grey box (13
// sensors on both channels, 2 lags, the blank) takes 32 IDs. With the once-step over several
// actions the flag is set in the last of them.
//
// One writer per setting datum. With a whirling plan on the same axis (whirl plan
// --with-drift-action), the plan's actions write their K0 into $AC_PARAM[workpiece_k0_param]
// instead of SD43900 (they still own SD43910/SD43920), and this action writes
//   SD43900 = machine K0 + $AC_PARAM[workpiece_k0_param],
// so the two never fight over SD43900; the plan program refuses to start (alarm) unless this
// action is running now (the liveness slot, see the $AC_PARAM layout below), and a plan that
// writes the setting data itself refuses while it runs. The drift action's IDs must lie above the
// plan's: actions
// run in ID order each cycle, so the plan's K0 is written before it is added (no cycle of lag).
//
// The machine's slope (optional second model, e.g. the Z feed screw growing from its fixed
// bearing, trained on a lead-slope channel such as zscrew_per_1000_um). Its output g [um per 1000
// mm] is the growth of the error with the distance from the fixed end P_b (profile drift.slope):
//   e(P) = e_K + g * sigma * (P - P_b) / 1000   [um along error_direction],
// sigma = growth_direction (+1: the distance from the fixed end grows towards +axis). So the
// machine alone is dK_m(P) = K_m + S_m (P - P_b) with K_m = s e_K / 1000 mm and
// S_m = s sigma g / 1e6 (mm/mm), written as SD43900 = K_m, SD43910 = S_m, SD43920 = P_b.
// Combined with a plan that hands its slope over too (workpiece_slope_param: the plan writes its
// K0_w, S_w, P_w into $AC_PARAM[workpiece_k0_param], [workpiece_slope_param], [.. + 1]), the sum
//   dK(P) = K0_w + S_w (P - P_w) + K_m + S_m (P - P_b)
// is written with the plan's reference as the common one:
//   SD43920 = P_w,  SD43910 = S_w + S_m,  SD43900 = K0_w + K_m + S_m (P_w - P_b),
// which equals the sum at every P; this action is then the only writer of all three.
//
// The grey box's blank term (drift/grey_box.h; BlankTerm below): the slope also carries
// g_b (B(t_0) - 20), B the first-order lag (blank tau) of the blank sensor, LATCHED at the cut
// start t_0. This action runs B every cycle into $AC_PARAM[blank_param] (profile
// drift.blank_param), and S_m reads the latched value from $AC_PARAM[blank_param + 1]:
//   S_m = s * sigma * (g0 + sum g_f x_f + g_b ($AC_PARAM[blank_param + 1] - 20)) / 1e6.
// The workpiece plan (sinumerik.h PlanOptions::blank_param) copies [blank_param] into
// [blank_param + 1] with its first segment at the thread start and writes 20 (no blank term)
// back at the thread end, in its undo of an aborted run and in its reset program; this
// program's preamble writes 20 there. Without a plan the part program latches it (the header
// says how). The liveness mode is then 3 (owns SD43900-43920 and reads the latch): a plan that
// does not latch refuses to start beside it (a blank term silently missing).
// The grey box's inputs are absolute temperatures referred to 20 degC: GreyBoxActionModels gives
// its offset and slope as two models with reference_C = 20, run with reference "model".
//
// The programs save what they find (R<n> SD43900, marker R<n+1>; with a slope R<n+2> SD43910,
// R<n+3> SD43920, slope marker R<n+4>; n = save_r_first, R<n>..R<n+4> reserved) and the reset
// program cancels the actions and restores them, so the control ends as it was found. A program
// without a slope gives back a slope an aborted slope run left behind (R<n+4> = 1).
// Not verified on a control here: the access level of main-run writes and whether IDS actions
// survive a reset on every software version (docs/840d.md).
#include <map>
#include <string>
#include <vector>

#include "drift/grey_box.h"
#include "drift/model.h"
#include "interp/control_requirements.h"
#include "interp/sinumerik.h"

namespace whirl::interp {

/// One analog input: value = scale * $A_INA[index] + offset (degC for a sensor).
struct AnalogInput {
  int index = 1;        ///< $A_INA[index], 1..MD10300 (1..999 when the count is not stated)
  double scale = 1.0;   ///< per input unit (e.g. 0.1 degC per unit), 1e-6 <= |scale| <= 1e3
  double offset = 0.0;  ///< degC (or the input's unit), |offset| <= 1e4
};
/// Bounds of an analog input's mapping. The scale is printed with 10 decimals
/// (kDecimalsDriftCoefficient): at 1e-6 it keeps 5 significant digits, below it a sensor would
/// fade out of the program (1e-12 prints as 0.0000000000); 1e3 per unit is far above any
/// transducer (a 0-10 V input over 0-100 degC is 0.01 degC per mV). An offset beyond 1e4 (degC or
/// the input's unit) is a typing error, not a transducer.
inline constexpr double kMinAnalogScale = 1e-6;
inline constexpr double kMaxAnalogScale = 1e3;
inline constexpr double kMaxAnalogOffset = 1e4;
inline constexpr int kMaxAnalogIndex = 999;
/// Interpolation cycle bounds [ms]: a SINUMERIK interpolation cycle is a few milliseconds;
/// outside 0.1..100 ms the lag factors per cycle would be wrong by orders of magnitude.
inline constexpr double kMinIpoCycleMs = 0.1;
inline constexpr double kMaxIpoCycleMs = 100.0;

/// The control's own limits a program depends on (machine data, from the machine profile's
/// "control" object; -1: not stated, then not checked, and the headers still name what each
/// program needs).
struct ControlLimits {
  int analog_inputs = -1;  ///< MD10300 $MN_FASTIO_ANA_NUM_INPUTS: NCK analog inputs, 0..999
  int sync_elements = -1;  ///< MD28250 $MC_MM_NUM_SYNC_ELEMENTS: synchronized-action elements
  int ac_params = -1;      ///< MD28254 $MC_MM_NUM_AC_PARAM: $AC_PARAM[0..n-1] exist, 1..10000
  bool Stated() const { return analog_inputs >= 0; }
  void Validate() const;  ///< InputError naming the machine datum and the rule
};

enum class DriftReference { kModel, kStart };
std::string ToString(DriftReference r);                    ///< "model" / "start"
DriftReference ParseDriftReference(const std::string& s);  ///< InputError otherwise

struct DriftActionOptions {
  std::string axis = "Z";
  ControlDk control_dk = ControlDk::kAdded;
  int error_direction = 1;    ///< +1 / -1, see the header comment
  double ipo_cycle_ms = 4.0;  ///< interpolation cycle of the control [ms], (0, 100]
  int sync_id_first = 1;      ///< IDS range of the drift action, within 1..255
  int sync_id_last = 255;
  int param_first = 0;          ///< first $AC_PARAM slot used (0..9999): the liveness slot
  /// Last $AC_PARAM slot the action may use (>= param_first + 3); -1: up to 9999. A model that
  /// needs more slots is an InputError naming both.
  int param_last = -1;
  int save_r_first = 80;        ///< R<n> saved SD43900, R<n+1> marker (1 while active)
  int workpiece_k0_param = -1;  ///< >= 0: add $AC_PARAM[n] (the whirling plan's K0)
  /// >= 0: the plan's SD43910 in $AC_PARAM[n], its SD43920 in $AC_PARAM[n + 1] (this action owns
  /// SD43910/SD43920 too); needs workpiece_k0_param.
  int workpiece_slope_param = -1;
  /// >= 0: the grey box's blank estimate B in $AC_PARAM[n] (this action writes it every cycle)
  /// and its value latched at the cut start in $AC_PARAM[n + 1] (the plan writes it); outside
  /// the action's own slots and the workpiece slots (profile drift.blank_param).
  int blank_param = -1;
  bool has_slope = false;          ///< the profile's drift.slope object is present
  double slope_fixed_end_mm = 0;   ///< P_b: axis position (MCS) of the zero of the growth, mm
  int slope_growth_direction = 1;  ///< sigma: +1 distance from P_b grows towards +axis, or -1
  /// First of four SETAL numbers (65000..69996, user cycle alarms): + 0..2 the plans' liveness check
  /// (sinumerik.h PlanOptions::drift_alive_param), + 3 this program finds a plan's compensation
  /// still active (R<plan_marker_r> = 1: run the plan's reset program first); after it the
  /// program jumps to its end (sinumerik.h CheckOrAlarm) and changes nothing, whatever the
  /// alarm's response.
  int missing_alarm = 65000;
  int plan_marker_r = -1;  ///< the plans' marker R (profile save_r_first + 3); -1: not checked
  DriftReference reference = DriftReference::kModel;
  std::map<std::string, AnalogInput> inputs;  ///< by column name (sensors and extra inputs)
  ControlLimits control;  ///< MD10300, MD28250, MD28254 (from the profile)
  /// The program's name and its reset program's on the control (the files' stems); checked by
  /// CheckProgramName and CheckDistinctProgramNames (sinumerik.h).
  std::string program_name = "WHIRL_DRIFT_COMP";
  std::string reset_program_name = "WHIRL_DRIFT_COMP_RESET";

  /// InputError naming the field and the rule: every bound above, IDs within 1..255, alarms
  /// within the user cycle alarms, analog indices within MD10300 and slots below MD28254.
  void Validate() const;
};

/// The neutral value of the latched blank slot [degC]: the blank term g_b (B - 20) is 0.
inline constexpr double kBlankNeutralC = 20.0;

/// The grey box's blank term of the slope (see the header comment): g_b (B_latched - 20) um per
/// 1000 mm, B the first-order lag tau_min of `sensor` [degC]; min_c..max_c the range B took in
/// training (the slope bound reads it).
struct BlankTerm {
  std::string sensor;
  double tau_min = 60;
  double um_per_1000_per_k = 0;
  double min_c = 20, max_c = 20;
};

/// The grey box (drift/grey_box.h) as this action runs it: the offset (K0 um) and slope (um per
/// 1000 mm, g0 its intercept) models with reference_C = 20 (drift/grey_box_io.h
/// GreyBoxControlModels; run them with reference "model") and the blank term (none without a
/// blank sensor). InputError for a model without an offset or a slope sensor.
struct GreyBoxAction {
  drift::DriftModel offset, slope;
  bool has_blank = false;
  BlankTerm blank;
  const BlankTerm* Blank() const { return has_blank ? &blank : nullptr; }
};
GreyBoxAction GreyBoxActionModels(const drift::GreyBoxModel& model);

/// One component of a mixed drift action (docs/machine-evaluation.md "Fourteenth round:
/// adoption"): the line sum_j w_j c_j, c_j the component's own line (K0 from `offset`, the slope
/// from `slope` with its `blank` term), each component with its own inputs, lags, reference
/// slots and init flags. Its K_j and S_j are accumulated in slots of their own every cycle and
///   SD43900 K_m = sum_j w_j K_j,  S_m = sum_j w_j S_j  (a component without a slope adds 0),
/// then composed with a plan's slots as for one model; the blank term belongs to its component's
/// S_j, so it is weighted by that w_j. Every component runs with the options' reference: mix a
/// model with sensors referred to `reference_C` (the grey box, reference "model") only with
/// models without sensors (the sensor-free rules warmup and schedule). One component of weight 1
/// is the single-model program (byte for byte). At most one component carries a blank term;
/// weights within (0, 1], summing to 1 (within 1e-9).
struct DriftComponent {
  const drift::DriftModel* offset = nullptr;
  const drift::DriftModel* slope = nullptr;
  const BlankTerm* blank = nullptr;
  double weight = 1;
};

/// The fourteenth round's mix as the action's components (docs/machine-evaluation.md
/// "Fourteenth round: adoption"; drift/grey_mix.h): the grey box (offset, slope and blank term)
/// with `grey_weight` and a sensor-free rule's offset and slope models with 1 - w; the grey box
/// alone for w = 1. The components point into `grey` and the rule's models. InputError for a rule
/// that reads sensors (the program runs one reference, the grey box's: reference "model").
std::vector<DriftComponent> GreyMixComponents(const GreyBoxAction& grey,
                                              const drift::DriftModel& rule_offset,
                                              const drift::DriftModel& rule_slope,
                                              double grey_weight);

/// How many $AC_PARAM slots the action uses for `model` (features, references, flag) and the
/// optional slope model (its features, references, flag, and one slot for S_m).
int DriftParamCount(const drift::DriftModel& model, const drift::DriftModel* slope = nullptr,
                    const BlankTerm* blank = nullptr);

/// The NC program (subprogram, .SPF, ends in M17) that installs the static actions. `slope`
/// (optional) is the machine's slope model (see the header comment). InputError for a network
/// model, a dynamic model without a time unit of minutes, a missing analog input, an ID range or
/// $AC_PARAM range (param_first..param_last, below MD28254) too small, a line longer than the
/// control's 512 characters, a slope model without the profile's slope object, or a slope model
/// with a plan that writes SD43910 itself (two writers), a blank term without a slope model, the
/// profile's blank_param or reference "model". The header names the prerequisites: MD10300 for
/// the analog inputs read, MD28254 for the slots, MD28250 for the actions.
std::string FormatDriftNcProgram(const drift::DriftModel& model, const DriftActionOptions& options,
                                 const std::string& model_source = "",
                                 const drift::DriftModel* slope = nullptr,
                                 const BlankTerm* blank = nullptr);

/// The same for a mixed line (DriftComponent): the header names each component and its weight,
/// the model lines, IDs, slots and the control's prerequisites count every component.
/// InputError as above, and for no component, a weight outside (0, 1] or weights not summing
/// to 1, more than one blank term, or a component without an offset model.
std::string FormatDriftNcProgram(const std::vector<DriftComponent>& components,
                                 const DriftActionOptions& options,
                                 const std::string& model_source = "");

/// The program that cancels the drift action's IDs and restores the saved setting data (SD43900
/// if R<n+1> = 1, SD43910/SD43920 if R<n+4> = 1).
std::string FormatDriftNcResetProgram(const DriftActionOptions& options);

/// The same model(s) for a PLC: '#' comments with the formulas, then one row per feature:
/// output,feature,input,ain_index,scale,offset,reference_C,tau_min,a_per_cycle,coefficient_per_unit
/// where output is "k0_mm" (the offset model; coefficient in mm per unit) or "slope" (the slope
/// model: S_m, coefficient in mm/mm per unit), each beginning with a row "intercept", and with a
/// blank term a last slope row "blank_latched" (its lag; the value at the cut start minus 20
/// degC times the coefficient). Fixed decimals.
std::string FormatDriftPlcCsv(const drift::DriftModel& model, const DriftActionOptions& options,
                              const drift::DriftModel* slope = nullptr,
                              const BlankTerm* blank = nullptr);

/// The same for a mixed line: with more than one component every row is tagged by its
/// component (1-based) and weight in two leading columns component,weight, and the comment says
/// K_m = sum of weight * each component's k0_mm sum (S_m likewise).
std::string FormatDriftPlcCsv(const std::vector<DriftComponent>& components,
                              const DriftActionOptions& options);

/// The coefficients the control applies: c_0 = s * b0 / 1000 [mm], c_f = s * b_f / 1000
/// [mm per unit], rounded to kDecimalsDriftCoefficient as printed.
Eigen::VectorXd DriftControlCoefficients(const drift::DriftModel& model,
                                         const DriftActionOptions& options);

/// The slope model's coefficients the control applies: S_m = c_0 + sum c_f x_f with
/// c = s * sigma * b / 1e6 (mm/mm per unit), rounded to kDecimalsDriftSlopeCoefficient.
Eigen::VectorXd DriftSlopeCoefficients(const drift::DriftModel& slope,
                                       const DriftActionOptions& options);

/// The largest |S_m| the slope model gives over its training ranges (a box bound: |c_0| +
/// sum |c_f| max(|min_f|, |max_f|)), mm/mm. The plan's slopes plus this must stay within MD32760
/// (machine_report/machine_nc.h checks it for the combined programs).
/// With a blank term, + |c_b| max(|min_c - 20|, |max_c - 20|).
double DriftSlopeBound(const drift::DriftModel& slope, const DriftActionOptions& options,
                       const BlankTerm* blank = nullptr);
/// The blank term's coefficient the control applies: c_b = s * sigma * g_b / 1e6 (mm/mm per K),
/// rounded to kDecimalsDriftSlopeCoefficient.
double DriftBlankCoefficient(const BlankTerm& blank, const DriftActionOptions& options);

/// What the control must provide for the drift program (control_requirements.h), the same
/// thresholds its header states: MD10300 >= the largest $A_INA index read, MD28254 >= the last
/// $AC_PARAM slot + 1, MD28250 room for its static actions, MD32750 bit 0 (and bit 1 with a
/// slope model that owns SD43910/SD43920) on the axis and, with a slope model, MD32760 >= its
/// slope bound (DriftSlopeBound); each with the profile's value when options.control states it.
/// InputError as FormatDriftNcProgram for a model it cannot write.
std::vector<ControlRequirement> DriftRequirements(const drift::DriftModel& model,
                                                  const DriftActionOptions& options,
                                                  const drift::DriftModel* slope = nullptr,
                                                  const BlankTerm* blank = nullptr);

/// The same for a mixed line (DriftComponent); MD32760 against sum_j w_j times each
/// component's slope bound.
std::vector<ControlRequirement> DriftRequirements(const std::vector<DriftComponent>& components,
                                                  const DriftActionOptions& options);
/// A mixed line's slope bound: sum_j w_j DriftSlopeBound of component j (0 without a slope).
double DriftSlopeBound(const std::vector<DriftComponent>& components,
                       const DriftActionOptions& options);

inline constexpr int kDecimalsDriftWeight = 10;            ///< a component's weight w_j
inline constexpr int kDecimalsDriftCoefficient = 10;       ///< mm per K (or per input unit)
inline constexpr int kDecimalsDriftSlopeCoefficient = 14;  ///< mm/mm per K: 1e-14 per K
inline constexpr int kDecimalsLagFactor = 15;              ///< a = 1 - exp(-T_ipo / tau)

}  // namespace whirl::interp
