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

namespace whirl::plan {
namespace {

using report::Cell;

// The plan's setting data, one row per segment, and the restoring row at the thread end.
report::Table SettingDataTable(const interp::CompensationPlan& plan, bool machine_coordinates) {
  const std::string unit = machine_coordinates ? "[mm, MCS]" : "[mm from the thread start]";
  report::Table t;
  t.header = {"segment", "written when " + plan.options.axis + " passes " + unit,
              "SD43900 K0 [mm]", "SD43910 slope [-]", "SD43920 reference " + unit};
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const interp::CompensationSegment& s = plan.segments[i];
    t.rows.push_back({std::to_string(i + 1), FormatFixed(s.p_a_mm, interp::kDecimalsPositionMm),
                      FormatFixed(s.sd43900_mm, interp::kDecimalsSd43900Mm),
                      FormatFixed(s.sd43910, interp::kDecimalsSd43910),
                      FormatFixed(s.sd43920_mm, interp::kDecimalsPositionMm)});
  }
  if (!plan.segments.empty()) {
    Cell what("the values found before the cut are written back (thread end)");
    what.colspan = 3;
    what.left = true;
    t.rows.push_back({"restore",
                      FormatFixed(plan.segments.back().p_b_mm, interp::kDecimalsPositionMm), what});
  }
  return t;
}

std::vector<report::Block> LoadBlocks(const ControlLoad& load) {
  using report::Bold;
  using report::MakeBlock;
  using report::Text;
  std::vector<report::Block> b;
  b.push_back(MakeBlock(report::Heading{3, load.heading, ""}));
  report::Paragraph files{{Bold("Files onto the control:"), Text(" ")}, report::Tone::kNormal};
  if (load.files.empty()) files.spans.push_back(Text(load.no_files));
  for (std::size_t i = 0; i < load.files.size(); ++i) {
    if (i) files.spans.push_back(Text("; "));
    files.spans.push_back(report::Link(load.files[i].first, load.files[i].first));
    files.spans.push_back(Text(" (" + load.files[i].second + ")"));
  }
  if (!load.files.empty()) files.spans.push_back(Text("."));
  b.push_back(MakeBlock(files));
  if (!load.call_order.empty())
    b.push_back(MakeBlock(report::Paragraph{{Bold("Call:"), Text(" " + load.call_order)}}));
  b.push_back(MakeBlock(report::Paragraph{
      {Bold("Setting data the plan writes"),
       Text(" (axis " + load.plan.options.axis + ", sign " +
            interp::ToString(load.plan.options.sign) + "):")}}));
  b.push_back(MakeBlock(SettingDataTable(load.plan, load.machine_coordinates)));
  if (!load.plan_note.empty())
    b.push_back(MakeBlock(report::Paragraph{{Text(load.plan_note)}, report::Tone::kSmall}));
  report::List needs;
  for (const interp::ControlRequirement& r : load.requirements)
    needs.items.push_back({Text(interp::ToString(r))});
  if (!load.profile_note.empty()) needs.items.push_back({Text(load.profile_note)});
  if (!needs.items.empty()) {
    b.push_back(MakeBlock(report::Paragraph{{Bold("Machine data the programs need"),
                                             Text(" (check once on the control):")}}));
    b.push_back(MakeBlock(needs));
  }
  if (!load.after_abort.empty())
    b.push_back(
        MakeBlock(report::Paragraph{{Bold("After an aborted cut:"), Text(" " + load.after_abort)}}));
  return b;
}

}  // namespace

report::Box LoadBox(const std::vector<ControlLoad>& loads) {
  report::Box box;
  box.id = "load";
  box.blocks.push_back(report::MakeBlock(report::Heading{2, "Load onto the control", ""}));
  box.blocks.push_back(report::MakeBlock(report::Paragraph{
      {report::Text("What to take to the SINUMERIK 840D. The links open the files written with "
                    "this report. The programs were not run on a real control here: check the "
                    "sign once with a constant SD43900 test value and a dial gauge before the "
                    "first cut.")},
      report::Tone::kSmall}));
  for (const ControlLoad& load : loads) {
    const std::vector<report::Block> b = LoadBlocks(load);
    box.blocks.insert(box.blocks.end(), b.begin(), b.end());
  }
  return box;
}

}  // namespace whirl::plan
