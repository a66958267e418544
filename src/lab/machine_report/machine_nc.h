#pragma once
// The combined 840D programs of one screw on a drifting whirling machine (machine_eval.h):
// the workpiece plan (the network's curve, interp/sinumerik.h) and the live machine-drift action
// (the offset model and the Z feed screw's slope model, interp/drift_action.h) in one pair of
// programs in which each setting datum has one writer:
//   the plan writes its K0_w, SD43910 S_w and SD43920 P_w into $AC_PARAM (profile
//   drift.workpiece_k0_param, drift.workpiece_slope_param and + 1);
//   the drift action writes SD43920 = P_w, SD43910 = S_w + S_m, SD43900 = K0_w + K_m +
//   S_m (P_w - P_b), K_m from the offset model, S_m from the slope model (um per 1000 mm) about
//   the screw's fixed bearing P_b.
// The drift models are what a shop can train: the grey box of both_grey where the evaluation
// picks it (BuildCombinedGreyPrograms: absolute temperatures, reference "model", the blank
// latched by the plan at the thread start), else the sensor model of the evaluation's both_shop
// (machine_eval/shop_models.h, from probe, laser and lead measurements only), its inputs the
// sensors and the control's duty signals the profile maps to analog inputs. Its rises and lags
// count from the day's power-on (drift/joint.h), so the drift action starts at power-on and runs
// all day (reference "start": the temperatures when it starts).
// Coordinates (machine/field.h): the tool is z mm from the chuck face, the cut runs towards the
// chuck, z(t) = z_0 - v_f t. The plan's program zero is taken at the chuck face with the program
// coordinate -direction * z (the travel runs towards the chuck), so the thread start is
// start_position_mm = -direction z_0 and the axis reads P = machine_offset_mm - direction z. The
// profile must agree with the simulated machine: error_direction = growth_direction = direction
// (the machine error is positive towards the chuck, the direction of travel), and
// drift.slope.fixed_end_position_mm = P at z = z_fixed = machine_offset_mm - direction z_fixed; a
// profile that does not is an InputError naming the field, its value and the value the machine
// implies. Shipped profile for the simulated machine: datasets/machines/whirling_840d.json.
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "drift/grey_box.h"
#include "drift/model.h"
#include "fit/arctan_curve.h"
#include "interp/control_requirements.h"
#include "interp/drift_action.h"
#include "interp/machine_profile.h"
#include "interp/sinumerik.h"
#include "screw/screw.h"

namespace whirl::machine_report {

struct CombinedPrograms {
  interp::CompensationPlan plan;       ///< the workpiece plan, handing K0 and slope over
  interp::DriftActionOptions drift;    ///< the drift action's options (from the profile)
  std::string plan_nc, plan_reset_nc;  ///< .SPF subprograms
  std::string drift_nc, drift_reset_nc, drift_plc_csv;
  /// What the control must provide for both programs together, each datum once
  /// (interp::MergeRequirements of the plan's and the drift action's), with the profile's values.
  std::vector<interp::ControlRequirement> requirements;
  bool grey = false;  ///< the drift action runs the grey box (BuildCombinedGreyPrograms)
  bool mixed = false;  ///< ... mixed with a sensor-free rule (BuildCombinedMixPrograms)
};

/// Builds both programs. `plan_options` gives the tolerance and check step (the profile sets
/// everything else); `offset` and `slope` are the machine's drift models (K0 um, slope um per
/// 1000 mm, with their training ranges), `z_fixed_mm` the fixed bearing they are about (mm from
/// the chuck face). InputError when the profile lacks the drift object, its slope object or
/// workpiece_slope_param, disagrees with the machine (see above), or when a program cannot be
/// written (IDs, MD32760, analog inputs, $AC_PARAM slots).
CombinedPrograms BuildCombinedPrograms(
    const fit::ArctanCurve& curve, const screw::Kinematics& kinematics, double thread_length_mm,
    const interp::PlanOptions& plan_options, const drift::DriftModel& offset,
    const drift::DriftModel& slope, double z_fixed_mm, const interp::MachineProfile& profile,
    const std::string& curve_source, const std::string& model_source);

/// The same with the grey box (drift/grey_box.h) as the machine's models: its offset and slope
/// (absolute temperatures, reference "model") and the blank estimate the plan latches at the
/// thread start (interp/drift_action.h BlankTerm; profile drift.blank_param), about its own
/// z_ref (the fixed bearing). InputError as above, or when the profile has no drift.blank_param
/// for a grey box with a blank sensor.
CombinedPrograms BuildCombinedGreyPrograms(
    const fit::ArctanCurve& curve, const screw::Kinematics& kinematics, double thread_length_mm,
    const interp::PlanOptions& plan_options, const drift::GreyBoxModel& grey,
    const interp::MachineProfile& profile, const std::string& curve_source,
    const std::string& model_source);

/// The fourteenth round's grey_short_mix (docs/machine-history.md "Fourteenth round:
/// adoption"; machine_eval/strategies.h MixedLines): the machine line w grey + (1 - w) rule, the
/// drift action as two components (interp::DriftComponent): the grey box with weight w (its
/// K0, slope and latched blank term) and the sensor-free base rule's offset and slope models
/// (drift/joint.h ToDriftModels with their training ranges, machine_eval::ShopControlModels)
/// with 1 - w, all run with reference "model" (the rule has no sensor: its duty inputs are read
/// as they are). w = 1: BuildCombinedGreyPrograms itself. InputError as above, for a w outside
/// (0, 1] or a rule that reads sensors.
CombinedPrograms BuildCombinedMixPrograms(
    const fit::ArctanCurve& curve, const screw::Kinematics& kinematics, double thread_length_mm,
    const interp::PlanOptions& plan_options, const drift::GreyBoxModel& grey,
    const drift::DriftModel& rule_offset, const drift::DriftModel& rule_slope,
    double grey_weight, const interp::MachineProfile& profile, const std::string& curve_source,
    const std::string& model_source);

/// grey_short_mix's drift action in a report (machine_report.h): it runs in place of
/// WHIRL_DRIFT_COMP with the grey box's plan (the same IDs and slots), under these names.
inline constexpr const char* kMixDriftProgramName = "WHIRL_DRIFT_MIX";
inline constexpr const char* kMixDriftResetProgramName = "WHIRL_DRIFT_MIX_RESET";
/// Its files in `dir`: WHIRL_DRIFT_MIX.SPF, WHIRL_DRIFT_MIX_RESET.SPF, WHIRL_DRIFT_MIX_PLC.csv.
std::vector<std::pair<std::filesystem::path, std::string>> MixDriftProgramFiles(
    const std::filesystem::path& dir, const CombinedPrograms& mix);

/// The files of the programs in `dir` (created if needed): WHIRL_TEMP_COMP.SPF,
/// WHIRL_TEMP_COMP_RESET.SPF, WHIRL_DRIFT_COMP.SPF, WHIRL_DRIFT_COMP_RESET.SPF,
/// WHIRL_DRIFT_COMP_PLC.csv, as (path, text) pairs for core's WriteFilesAtomic.
std::vector<std::pair<std::filesystem::path, std::string>> CombinedProgramFiles(
    const std::filesystem::path& dir, const CombinedPrograms& programs);

}  // namespace whirl::machine_report
