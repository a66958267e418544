#include "machine_report/machine_nc.h"

#include <cmath>

#include "core/error.h"
#include "core/numbers.h"
#include "plan/load.h"

namespace whirl::machine_report {
namespace {

void Require(bool ok, const interp::MachineProfile& p, const std::string& field,
             const std::string& rule) {
  if (!ok) throw InputError("machine profile '" + p.source + "', " + field + ": " + rule);
}

// The profile against the simulated machine's geometry (see the header).
void CheckAgainstMachine(const interp::MachineProfile& p, const interp::DriftActionOptions& d,
                         double fixed_end_mm) {
  Require(d.has_slope, p, "drift.slope", "missing (the Z feed screw's fixed end)");
  Require(d.workpiece_slope_param >= 0, p, "drift.workpiece_slope_param",
          "missing: the plan must hand its SD43910/SD43920 to the drift action");
  const std::string dir = std::to_string(p.direction);
  Require(d.error_direction == p.direction, p, "drift.error_direction",
          std::to_string(d.error_direction) + " must equal direction " + dir +
              " (the machine error is positive towards the chuck, the direction of travel)");
  Require(d.slope_growth_direction == p.direction, p, "drift.slope.growth_direction",
          std::to_string(d.slope_growth_direction) + " must equal direction " + dir +
              " (the distance from the fixed bearing grows towards the chuck)");
  Require(std::abs(d.slope_fixed_end_mm - fixed_end_mm) < 1e-3, p,
          "drift.slope.fixed_end_position_mm",
          FormatFixed(d.slope_fixed_end_mm, 4) + " mm, but the machine's fixed bearing " +
              "(z_fixed) sits at " + FormatFixed(fixed_end_mm, 4) + " mm (MCS)");
}

// The machine's models as the drift action runs them: one model, or the components of a mixed
// line (interp::DriftComponent), each with a slope model.
struct MachineModels {
  std::vector<interp::DriftComponent> parts;
  interp::DriftReference reference;
  const interp::BlankTerm* Blank() const {
    for (const interp::DriftComponent& c : parts)
      if (c.blank) return c.blank;
    return nullptr;
  }
};

CombinedPrograms Build(const fit::ArctanCurve& curve, const screw::Kinematics& kinematics,
                       double thread_length_mm, const interp::PlanOptions& plan_options,
                       const MachineModels& machine, double z_fixed_mm,
                       const interp::MachineProfile& profile, const std::string& curve_source,
                       const std::string& model_source) {
  const interp::BlankTerm* blank = machine.Blank();
  CombinedPrograms out;
  interp::PlanOptions po = plan_options;
  profile.ApplyCombinedTo(po);
  if (!blank) po.blank_param = -1;  // nothing to latch: the plan leaves the slots alone
  // Program zero at the chuck face, the program coordinate -direction * z: the cut runs towards
  // the chuck (z falls) in the direction of travel.
  po.start_position_mm = -po.direction * kinematics.thread_start_position_mm;
  out.drift = profile.DriftOptions();
  out.drift.reference = machine.reference;
  Require(!blank || out.drift.blank_param >= 0, profile, "drift.blank_param",
          "missing: the grey box's blank estimate and its latch at the cut start need two "
          "$AC_PARAM slots");
  const double z0 = kinematics.thread_start_position_mm;
  CheckAgainstMachine(
      profile, out.drift,
      po.machine_offset_mm + po.start_position_mm + po.direction * (z0 - z_fixed_mm));
  out.plan = interp::BuildPlan(curve, kinematics.axial_feed_mm_s, thread_length_mm, po);
  interp::NcProgramInfo info;
  info.curve_source = curve_source;
  out.plan_nc = interp::FormatNcProgram(out.plan, info);
  out.plan_reset_nc = interp::FormatNcResetProgram(po, info);
  const double bound = interp::DriftSlopeBound(machine.parts, out.drift);
  if (out.plan.max_abs_slope + bound > po.md32760)
    throw InputError("combined programs: the plan's largest slope " +
                     FormatFixed(out.plan.max_abs_slope, interp::kDecimalsSd43910) +
                     " plus the machine slope's bound " +
                     FormatFixed(bound, interp::kDecimalsSd43910) +
                     " exceed MD32760 = " + FormatFixed(po.md32760, 4) + " (profile '" +
                     profile.source + "'): SD43910 could be capped mid-cut");
  out.drift_nc = interp::FormatDriftNcProgram(machine.parts, out.drift, model_source);
  out.drift_reset_nc = interp::FormatDriftNcResetProgram(out.drift);
  out.drift_plc_csv = interp::FormatDriftPlcCsv(machine.parts, out.drift);
  out.requirements = plan::WithProfileValues(
      interp::MergeRequirements(interp::DriftRequirements(machine.parts, out.drift),
                                interp::PlanRequirements(out.plan, info.program_name)),
      profile);
  return out;
}

}  // namespace

CombinedPrograms BuildCombinedPrograms(
    const fit::ArctanCurve& curve, const screw::Kinematics& kinematics, double thread_length_mm,
    const interp::PlanOptions& plan_options, const drift::DriftModel& offset,
    const drift::DriftModel& slope, double z_fixed_mm, const interp::MachineProfile& profile,
    const std::string& curve_source, const std::string& model_source) {
  return Build(curve, kinematics, thread_length_mm, plan_options,
               {{{&offset, &slope, nullptr, 1.0}}, interp::DriftReference::kStart}, z_fixed_mm,
               profile,
               curve_source, model_source);
}

CombinedPrograms BuildCombinedGreyPrograms(
    const fit::ArctanCurve& curve, const screw::Kinematics& kinematics, double thread_length_mm,
    const interp::PlanOptions& plan_options, const drift::GreyBoxModel& grey,
    const interp::MachineProfile& profile, const std::string& curve_source,
    const std::string& model_source) {
  const interp::GreyBoxAction a = interp::GreyBoxActionModels(grey);
  CombinedPrograms out = Build(curve, kinematics, thread_length_mm, plan_options,
                               {{{&a.offset, &a.slope, a.Blank(), 1.0}},
                                interp::DriftReference::kModel},
                               grey.z_ref_mm, profile, curve_source, model_source);
  out.grey = true;
  return out;
}

CombinedPrograms BuildCombinedMixPrograms(
    const fit::ArctanCurve& curve, const screw::Kinematics& kinematics, double thread_length_mm,
    const interp::PlanOptions& plan_options, const drift::GreyBoxModel& grey,
    const drift::DriftModel& rule_offset, const drift::DriftModel& rule_slope,
    double grey_weight, const interp::MachineProfile& profile, const std::string& curve_source,
    const std::string& model_source) {
  if (grey_weight == 1.0)  // MixedLines' w = 1: the grey box's line itself
    return BuildCombinedGreyPrograms(curve, kinematics, thread_length_mm, plan_options, grey,
                                     profile, curve_source, model_source);
  const interp::GreyBoxAction a = interp::GreyBoxActionModels(grey);
  CombinedPrograms out = Build(
      curve, kinematics, thread_length_mm, plan_options,
      {interp::GreyMixComponents(a, rule_offset, rule_slope, grey_weight),
       interp::DriftReference::kModel},
      grey.z_ref_mm, profile, curve_source, model_source);
  out.grey = true;
  out.mixed = true;
  return out;
}

std::vector<std::pair<std::filesystem::path, std::string>> MixDriftProgramFiles(
    const std::filesystem::path& dir, const CombinedPrograms& mix) {
  const std::string name = kMixDriftProgramName;
  return {{dir / (name + ".SPF"), mix.drift_nc},
          {dir / (std::string(kMixDriftResetProgramName) + ".SPF"), mix.drift_reset_nc},
          {dir / (name + "_PLC.csv"), mix.drift_plc_csv}};
}

std::vector<std::pair<std::filesystem::path, std::string>> CombinedProgramFiles(
    const std::filesystem::path& dir, const CombinedPrograms& p) {
  return {{dir / "WHIRL_TEMP_COMP.SPF", p.plan_nc},
          {dir / "WHIRL_TEMP_COMP_RESET.SPF", p.plan_reset_nc},
          {dir / "WHIRL_DRIFT_COMP.SPF", p.drift_nc},
          {dir / "WHIRL_DRIFT_COMP_RESET.SPF", p.drift_reset_nc},
          {dir / "WHIRL_DRIFT_COMP_PLC.csv", p.drift_plc_csv}};
}

}  // namespace whirl::machine_report
