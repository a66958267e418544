#include "plan/load.h"

#include "core/numbers.h"

namespace whirl::plan {

std::vector<interp::ControlRequirement> WithProfileValues(
    std::vector<interp::ControlRequirement> requirements, const interp::MachineProfile& profile) {
  const interp::ControlLimits& c = profile.control;
  for (interp::ControlRequirement& r : requirements) {
    if (r.datum.rfind("MD32760", 0) == 0 && r.axis == profile.axis) r.stated = profile.md32760;
    if (!c.Stated()) continue;
    if (r.datum.rfind("MD10300", 0) == 0) r.stated = c.analog_inputs;
    if (r.datum.rfind("MD28250", 0) == 0) r.stated = c.sync_elements;
    if (r.datum.rfind("MD28254", 0) == 0) r.stated = c.ac_params;
  }
  return requirements;
}

std::string ProfileNote(const interp::MachineProfile& profile) {
  const interp::ControlLimits& c = profile.control;
  if (!c.Stated()) return "";
  return "machine profile '" + profile.name + "' states: MD10300 " +
         std::to_string(c.analog_inputs) + " analog inputs, MD28250 " +
         std::to_string(c.sync_elements) + " synchronized-action elements, MD28254 " +
         std::to_string(c.ac_params) + " $AC_PARAM, MD32760 " + FormatFixed(profile.md32760, 4) +
         " on axis " + profile.axis +
         "; if the control's values differ, correct the profile and "
         "plan again";
}

ControlLoad PlanFilesLoad(const std::string& prefix, const std::string& program,
                          const std::string& plc_csv, const std::string& plan_json,
                          const interp::CompensationPlan& plan,
                          const interp::MachineProfile* profile) {
  ControlLoad load;
  load.plan = plan;
  load.files = {{prefix + program + ".SPF", "NC program"},
                {prefix + program + "_RESET.SPF", "its reset program"},
                {prefix + plc_csv, "PLC table: the same setting data per trigger position"},
                {prefix + plan_json, "plan document (JSON): for the record, not for the control"}};
  load.requirements = interp::PlanRequirements(plan, program);
  if (profile) {
    load.requirements = WithProfileValues(load.requirements, *profile);
    load.profile_note = ProfileNote(*profile);
  }
  load.call_order = "call " + program +
                    " before the cutting block, with the axis before the thread start; call " +
                    program + "_RESET after the cutting block.";
  load.after_abort = "call " + program +
                     "_RESET (it cancels the actions and writes back the setting data found "
                     "before the cut), move the axis before the thread start and cut the whole "
                     "thread again: there is no resume from mid-thread.";
  return load;
}

}  // namespace whirl::plan
