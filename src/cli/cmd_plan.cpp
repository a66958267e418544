// whirl plan: compensation points and SINUMERIK 840D temperature-compensation setting data
// (interp/sinumerik.h) for a screw, from a model's prediction (or given features).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <tuple>

#include "cli/commands.h"
#include "cli/common.h"
#include "plan/plan_document.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "fit/arctan_curve.h"
#include "interp/machine_profile.h"
#include "interp/sinumerik.h"
#include "workpiece/model.h"
#include "screw/screw.h"

namespace whirl::cli {
namespace {

struct PlanCliOptions {
  CurveSourceArgs source;
  double tolerance_um = interp::PlanOptions{}.tolerance_um;
  double check_step_s = interp::PlanOptions{}.check_step_s;
  // Machine facts: from --machine, each overridable; NAN / 0 / -1 / "" = not given.
  std::string machine_path;
  std::string axis;
  double start_position_mm = NAN;
  int direction = 0;
  double machine_offset_mm = NAN;
  std::string sign;
  std::string control_dk;
  double md32760 = NAN;
  int sync_id_first = -1;
  int sync_id_last = -1;
  int save_r_first = -1;
  int start_alarm = -1;
  std::string out_path;
  std::string csv_path;
  std::string nc_path;
  std::string reset_nc_path;
  bool with_drift_action = false;
  bool json = false;
};

// The control resources a profile reserves for whirl (IDs, R parameters, the start alarm): an
// explicit flag may repeat the profile's value but never contradict it; without a profile the
// IDs and R parameters come only from the flags (FormatNcProgram refuses a program without them).
void ApplyReservedFlags(const PlanCliOptions& o, interp::PlanOptions& p) {
  const bool profile = !o.machine_path.empty();
  for (const auto& [flag, key, given, value] :
       {std::tuple{"--sync-id-first", "sync_id_first", o.sync_id_first, &p.sync_id_first},
        {"--sync-id-last", "sync_id_last", o.sync_id_last, &p.sync_id_last},
        {"--save-r-first", "save_r_first", o.save_r_first, &p.save_r_first},
        {"--start-alarm", "start_alarm", o.start_alarm, &p.start_alarm}}) {
    if (given < 0) continue;
    if (profile && given != *value)
      throw InputError(std::string("plan: ") + flag + " " + std::to_string(given) +
                       " contradicts the machine profile '" + o.machine_path + "' (" + key + " " +
                       std::to_string(*value) +
                       "), which states what the machine builder reserved for whirl: drop the "
                       "flag or change the profile");
    *value = given;
  }
  if (o.sync_id_first > 0 && o.sync_id_last > 0 && o.sync_id_first > o.sync_id_last)
    throw InputError("plan: --sync-id-first " + std::to_string(o.sync_id_first) +
                     " is above --sync-id-last " + std::to_string(o.sync_id_last) +
                     ": the range runs from the first ID to the last");
  if (!profile && (o.sync_id_first < 0) != (o.sync_id_last < 0))
    throw InputError(
        "plan: --sync-id-first and --sync-id-last go together (the range whirl's programs "
        "cancel and use)");
}

// The plan options from the machine profile and the explicit flags; the machine-specific
// positions have no default (a wrong zero would put every trigger at the wrong place).
interp::PlanOptions ResolvePlanOptions(const PlanCliOptions& o) {
  interp::PlanOptions p;
  p.tolerance_um = o.tolerance_um;
  p.check_step_s = o.check_step_s;
  bool have_start = false, have_offset = false;
  if (!o.machine_path.empty()) {
    const interp::MachineProfile m = interp::LoadMachineProfile(o.machine_path);
    WarnIllustrativeProfile(m);
    if (o.with_drift_action)
      m.ApplyCombinedTo(p);
    else
      m.ApplyTo(p);
    have_start = m.start_position_mm.has_value();
    have_offset = true;
  }
  if (!o.axis.empty()) p.axis = o.axis;
  if (o.direction != 0) p.direction = o.direction;
  if (!o.control_dk.empty()) p.control_dk = interp::ParseControlDk(o.control_dk);
  if (!std::isnan(o.md32760)) p.md32760 = o.md32760;
  ApplyReservedFlags(o, p);
  if (!std::isnan(o.start_position_mm))
    p.start_position_mm = o.start_position_mm, have_start = true;
  if (!std::isnan(o.machine_offset_mm))
    p.machine_offset_mm = o.machine_offset_mm, have_offset = true;
  if (o.with_drift_action && o.machine_path.empty())
    throw InputError("plan: --with-drift-action needs --machine (its 'drift' object)");
  if (!have_start || !have_offset)
    throw InputError(std::string("plan: ") + (have_start ? "" : "--start-position-mm ") +
                     (have_start || have_offset ? "" : "and ") +
                     (have_offset ? "" : "--machine-offset-mm ") +
                     "required (or a --machine profile that holds them): there is no safe default "
                     "for where the thread starts on the machine");
  p.sign = o.sign.empty() ? interp::ExpectedSign(p.direction, p.control_dk)
                          : interp::ParseSignConvention(o.sign);
  if (p.sign != interp::ExpectedSign(p.direction, p.control_dk))
    throw InputError("plan: --sign " + o.sign + " contradicts direction " +
                     std::to_string(p.direction) + " and control_dk '" +
                     interp::ToString(p.control_dk) + "' (--direction, --control-dk or " +
                     (o.machine_path.empty() ? "their defaults" : "the machine profile") +
                     "): the growth points against the travel, so the sign must be '" +
                     interp::ToString(interp::ExpectedSign(p.direction, p.control_dk)) +
                     "' here; leave --sign out to have it derived");
  p.Validate();
  return p;
}

void Run(const PlanCliOptions& o) {
  CheckOutputs({{"--model", o.source.model_path},
                {"--screw", o.source.screw_path},
                {"--machine", o.machine_path}},
               {{"--out", o.out_path},
                {"--csv", o.csv_path},
                {"--nc", o.nc_path},
                {"--reset-nc", o.reset_nc_path}});
  const bool by_features =
      !std::isnan(o.source.max_elongation_um) || !std::isnan(o.source.settle_time_s);
  if (by_features == !o.source.model_path.empty())
    throw InputError("plan: give either --model M or --max-elongation-um L --settle-time-s T");
  const interp::PlanOptions options = ResolvePlanOptions(o);
  const screw::Screw screw = screw::ReadScrew(o.source.screw_path);
  const screw::Kinematics kin = screw::ComputeKinematics(screw);

  plan::PlanSource plan_source;
  std::string source;
  if (!by_features) {
    const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(o.source.model_path);
    const workpiece::Prediction pred = workpiece::Predict(model, screw.process);
    GuardTrainingDomain(pred.outside_domain, pred.outside_domain_fields, o.source.screw_path,
                        o.source.allow_extrapolation);
    plan_source = {o.source.model_path, pred, pred.mean};
    source = "model " + o.source.model_path + ", screw " + o.source.screw_path;
  } else {
    if (std::isnan(o.source.max_elongation_um) || std::isnan(o.source.settle_time_s))
      throw InputError("plan: --max-elongation-um and --settle-time-s go together");
    plan_source.features = {o.source.max_elongation_um, o.source.settle_time_s};
    source = "given features, screw " + o.source.screw_path;
  }
  CheckPlanFeatures(plan_source.features, by_features ? "--max-elongation-um/--settle-time-s"
                                                      : "prediction of " + o.source.model_path);
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures(
      plan_source.features, o.source.shape_k, o.source.time_exponent);
  const interp::CompensationPlan plan =
      interp::BuildPlan(curve, kin.axial_feed_mm_s, screw.thread_length_mm, options);
  const std::string provenance = "whirl plan (" + source + "), " + curve.Describe();
  const nlohmann::json j = plan::PlanDocument(plan, curve, screw, kin, plan_source, provenance);
  plan::WritePlanFiles({o.out_path, o.csv_path, o.nc_path, o.reset_nc_path}, j, plan, provenance,
                          curve.Describe() + " (" + source + ")");

  if (o.json) {
    PrintJson(j);
    return;
  }
  std::printf("%s\n", provenance.c_str());
  std::printf("axial feed %.4f mm/min, cutting time %.1f s over %.1f mm of thread\n",
              kin.axial_feed_mm_min, plan.cutting_time_s, plan.thread_length_mm);
  const std::string uniform = plan.uniform_point_count > 0
                                  ? std::to_string(plan.uniform_point_count)
                                  : std::string("more than 1000000");
  std::printf(
      "compensation points: %zu (%zu segments), uniform spacing needs %s for the same "
      "%.3g um bound\n",
      plan.point_count, plan.segments.size(), uniform.c_str(), options.tolerance_um);
  std::printf("largest |curve - compensation| on the check grid: %.4f um (tolerance %.4g um)\n",
              plan.max_deviation_um, options.tolerance_um);
  std::printf("largest |SD43910| %s (MD32760 cap %s), axis %s, sign %s, direction %+d\n",
              FormatFixed(plan.max_abs_slope, interp::kDecimalsSd43910).c_str(),
              FormatFixed(options.md32760, 4).c_str(), options.axis.c_str(),
              interp::ToString(options.sign).c_str(), options.direction);
  for (const auto& [path, what] : {std::pair{o.out_path, "plan JSON"},
                                   {o.csv_path, "PLC table"},
                                   {o.nc_path, "NC program"},
                                   {o.reset_nc_path, "NC reset program"}})
    if (!path.empty()) std::printf("written: %s (%s)\n", path.c_str(), what);
}

}  // namespace

void RegisterPlan(CLI::App& app) {
  auto o = std::make_shared<PlanCliOptions>();
  auto* sub = app.add_subcommand(
      "plan",
      "Plan SINUMERIK 840D temperature compensation of the thermal elongation for a screw:\n"
      "predict (max elongation, settle time) with --model (or give --max-elongation-um and\n"
      "--settle-time-s), build the arctan curve l(t) [um], choose the fewest breakpoints so the\n"
      "piecewise-linear compensation stays within --tolerance-um of the curve (dense while the\n"
      "curve moves, one flat segment on the plateau to the end of the thread), map time to axis\n"
      "position P(t) = machine offset + start + direction * feed * t [mm] with the screw's axial\n"
      "feed, and emit per segment A->B:\n"
      "  SD43900 $SA_TEMP_COMP_ABS_VALUE   = s l_A / 1000            [mm]\n"
      "  SD43910 $SA_TEMP_COMP_SLOPE       = s (l_B - l_A)/1000/(P_B - P_A) [-]\n"
      "  SD43920 $SA_TEMP_COMP_REF_POSITION = P_A                    [mm]\n"
      "The sign s follows the direction of travel: the cut runs towards the chuck, so the growth\n"
      "of the unmachined section points against the travel and s = -direction if the control\n"
      "adds dK to the setpoint (control_dk 'added', Siemens' K3 description), +direction if it\n"
      "subtracts it; --sign is optional and an inconsistent one is refused. Verify control_dk\n"
      "once on the machine (constant SD43900 test value, dial gauge).\n"
      "Machine facts come from --machine M.json (schema whirl.machine, see\n"
      "datasets/machines/example_840d.json): axis, direction, machine offset, control_dk and\n"
      "MD32760 (each overridable by its flag), and what the machine builder reserved for whirl:\n"
      "the synchronized-action IDs, R parameters and the start alarm (a flag that contradicts\n"
      "the profile is refused; without a profile --nc/--reset-nc need --sync-id-first,\n"
      "--sync-id-last and --save-r-first, there is no default). --start-position-mm and\n"
      "--machine-offset-mm have no default: give them or a profile.\n"
      "The NC program (--nc, a subprogram ending in M17: save it as .SPF) refuses to start with\n"
      "alarm --start-alarm unless the axis stands before the thread start (no resume from\n"
      "mid-thread; after any alarm it jumps to its end and changes nothing), cancels its ID\n"
      "range, saves the setting data it finds in R parameters,\n"
      "writes every segment, the first at the thread start, through synchronized actions (so\n"
      "the approach keeps what the control applied before) and restores the saved values at\n"
      "the thread end; --reset-nc writes the program to run after an aborted cut. The file\n"
      "names are the program names. Numbers: positions and SD43920 4 decimals [mm], SD43900 6\n"
      "[mm], SD43910 8 [-], identical in NC, PLC table and JSON. A slope above MD32760 is an\n"
      "error. Outputs: plan JSON (--out, schema whirl.plan, the same document as 'whirl demo'),\n"
      "PLC table CSV (--csv), NC programs (--nc, --reset-nc);\n"
      "all-or-nothing: if one cannot be written (missing directory, a directory, symlink, FIFO or\n"
      "device at the path) none is and previous files stay. Requires MD32750 = 3.");
  AddCurveSourceOptions(sub, &o->source, true);
  AddToleranceOption(sub, &o->tolerance_um);
  sub->add_option("--machine", o->machine_path,
                  "machine profile JSON (schema whirl.machine): axis, direction, machine offset, "
                  "control_dk, MD32760, ID range, R parameters")
      ->check(CLI::ExistingFile);
  sub->add_option("--axis", o->axis,
                  "axis name for $SA_TEMP_COMP_*[axis] and $AA_IM[axis] (default Z)")
      ->check(AxisName());
  sub->add_option("--start-position-mm", o->start_position_mm,
                  "axis position at the thread start (time 0), program coordinates [mm]; "
                  "required unless the profile has it")
      ->check(NumberIn(kAxisPositionRange));
  sub->add_option("--direction", o->direction,
                  "direction of travel along the axis while cutting: 1 or -1 (default 1)")
      ->check(CLI::IsMember({1, -1}));
  sub->add_option("--machine-offset-mm", o->machine_offset_mm,
                  "machine coordinate of the program zero on this axis [mm] (SD43920 and "
                  "$AA_IM are machine coordinates); required unless --machine")
      ->check(NumberIn(kAxisPositionRange));
  sub->add_option("--control-dk", o->control_dk,
                  "how the control applies dK: added (default) or subtracted")
      ->check(CLI::IsMember({"added", "subtracted"}));
  sub->add_option("--sign", o->sign,
                  "optional check: subtract (dK = -l) or add (dK = +l); must match the rule above")
      ->check(CLI::IsMember({"subtract", "add"}));
  sub->add_option("--md32760", o->md32760,
                  "MD32760 $MA_COMP_ADD_VELO_FACTOR of the axis: cap on |SD43910| (0-0.10], "
                  "default 0.01")
      ->check(Md32760Number());
  sub->add_option("--sync-id-first", o->sync_id_first,
                  "first synchronized-action ID whirl may use (1-255); no default: from the "
                  "profile, or required with --sync-id-last for --nc/--reset-nc without one; a "
                  "value that contradicts the profile is refused")
      ->check(NumberIn(1, 255));
  sub->add_option("--sync-id-last", o->sync_id_last,
                  "last synchronized-action ID whirl may use (1-255); the programs CANCEL the "
                  "whole range first, so it must be the range the machine builder reserved; no "
                  "default: from the profile, or required with --sync-id-first for "
                  "--nc/--reset-nc without one")
      ->check(NumberIn(1, 255));
  auto* save_r = sub->add_option("--save-r-first", o->save_r_first,
                                 "R<n>..R<n+3> keep the setting data found before the cut and a "
                                 "marker (0-9996); no default: from the profile, or required for "
                                 "--nc/--reset-nc without one; a value that contradicts the "
                                 "profile is refused")
                     ->check(NumberIn(0, 9996));
  AddDeprecatedAlias(sub, save_r, "--save-r");
  sub->add_option("--start-alarm", o->start_alarm,
                  "SETAL number raised when the program is called with the axis at or past the "
                  "thread start (user cycle alarms 65000-69999; default 65004 without a profile; "
                  "must match the profile's start_alarm)")
      ->check(NumberIn(interp::kUserAlarmFirst, interp::kUserAlarmLast));
  sub->add_option("--check-step-s", o->check_step_s,
                  "largest step of the grid the tolerance is checked on [s] (refined as needed)")
      ->capture_default_str()
      ->check(PositiveNumber());
  sub->add_option("--out", o->out_path, "write the plan JSON here");
  sub->add_option("--csv", o->csv_path, "write the PLC table (CSV) here");
  sub->add_option("--nc", o->nc_path,
                  "write the NC subprogram here (ends in M17: name it .SPF, e.g. "
                  "WHIRL_TEMP_COMP.SPF); its file name without the extension is the program name "
                  "on the control: two letters, then letters, digits or '_', at most 24 "
                  "characters");
  sub->add_flag("--with-drift-action", o->with_drift_action,
                "combined with the live drift action (whirl drift nc) on the same axis: the plan "
                "writes its K0 into the profile's drift.workpiece_k0_param and the drift action "
                "adds it into SD43900, its only writer; with the profile's "
                "drift.workpiece_slope_param the plan also hands its SD43910/SD43920 over and the "
                "drift action (with --slope-model) owns all three; the program raises the "
                "profile's alarm if the drift action is not active");
  sub->add_option("--reset-nc", o->reset_nc_path,
                  "write the reset subprogram for an aborted cut here (.SPF; a program name as "
                  "for --nc, not the same)");
  sub->add_flag("--json", o->json, "machine output: the plan JSON on stdout");
  sub->callback([o] { Run(*o); });
}

}  // namespace whirl::cli
