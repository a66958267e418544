#include "compare/control_box.h"

#include <algorithm>
#include <sstream>

#include "core/html_page.h"
#include "core/numbers.h"
#include "core/safe_text.h"

namespace whirl::compare {
namespace {

// The plan's setting data, one row per segment, and the restoring row at the thread end.
std::string SettingDataTable(const interp::CompensationPlan& plan) {
  std::ostringstream h;
  h << "<table><tr><th>segment</th><th>written when " << HtmlEscape(plan.options.axis)
    << " passes [mm, MCS]</th><th>SD43900 K0 [mm]</th><th>SD43910 slope [-]</th>"
       "<th>SD43920 reference [mm]</th></tr>\n";
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const interp::CompensationSegment& s = plan.segments[i];
    h << "<tr><td>" << i + 1 << "</td><td>" << FormatFixed(s.p_a_mm, interp::kDecimalsPositionMm)
      << "</td><td>" << FormatFixed(s.sd43900_mm, interp::kDecimalsSd43900Mm) << "</td><td>"
      << FormatFixed(s.sd43910, interp::kDecimalsSd43910) << "</td><td>"
      << FormatFixed(s.sd43920_mm, interp::kDecimalsPositionMm) << "</td></tr>\n";
  }
  if (!plan.segments.empty())
    h << "<tr><td>restore</td><td>"
      << FormatFixed(plan.segments.back().p_b_mm, interp::kDecimalsPositionMm)
      << "</td><td colspan='3' style='text-align:left'>the values found before the cut are "
         "written back (thread end)</td></tr>\n";
  h << "</table>\n";
  return h.str();
}

std::string Items(const std::vector<std::string>& lines) {
  std::string h = "<ul>\n";
  for (const auto& l : lines) h += "<li>" + HtmlEscape(l) + "</li>\n";
  return h + "</ul>\n";
}

std::string LoadHtml(const ControlLoad& load) {
  std::ostringstream h;
  h << "<h3>" << HtmlEscape(load.heading) << "</h3>\n";
  h << "<p><b>Files onto the control:</b> ";
  if (load.files.empty()) {
    h << HtmlEscape(load.no_files) << "</p>\n";
  } else {
    for (std::size_t i = 0; i < load.files.size(); ++i)
      h << (i ? "; " : "") << HtmlLink(load.files[i].first, load.files[i].first) << " ("
        << HtmlEscape(load.files[i].second) << ")";
    h << ".</p>\n";
  }
  if (!load.call_order.empty()) h << "<p><b>Call:</b> " << HtmlEscape(load.call_order) << "</p>\n";
  h << "<p><b>Setting data the plan writes</b> (axis " << HtmlEscape(load.plan->options.axis)
    << ", sign " << interp::ToString(load.plan->options.sign) << "):</p>\n"
    << SettingDataTable(*load.plan);
  if (!load.plan_note.empty()) h << "<p class='small'>" << HtmlEscape(load.plan_note) << "</p>\n";
  if (!load.prerequisites.empty())
    h << "<p><b>Machine data the programs need</b> (check once on the control):</p>\n"
      << Items(load.prerequisites);
  if (!load.after_abort.empty())
    h << "<p><b>After an aborted cut:</b> " << HtmlEscape(load.after_abort) << "</p>\n";
  return h.str();
}

}  // namespace

std::vector<std::string> NcPrerequisites(const std::string& nc_program) {
  std::vector<std::string> lines;
  std::istringstream in(nc_program);
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] != ';') {
      if (!lines.empty()) break;  // the header ends at the first statement
      continue;
    }
    for (const char* key : {"; requires ", "; uses "})
      if (line.rfind(key, 0) == 0) lines.push_back(line.substr(2));
  }
  return lines;
}

std::vector<std::string> ProfilePrerequisites(const interp::MachineProfile& profile) {
  std::vector<std::string> lines;
  const interp::ControlLimits& c = profile.control;
  if (c.Stated())
    lines.push_back("machine profile '" + profile.name + "' states: MD10300 " +
                    std::to_string(c.analog_inputs) + " analog inputs, MD28250 " +
                    std::to_string(c.sync_elements) + " synchronized-action elements, MD28254 " +
                    std::to_string(c.ac_params) + " $AC_PARAM, MD32760 " +
                    FormatFixed(profile.md32760, 4) + " on axis " + profile.axis +
                    "; if the control's values differ, correct the profile and plan again");
  return lines;
}

ControlLoad PlanFilesLoad(const std::string& prefix, const std::string& program,
                          const std::string& plc_csv, const std::string& plan_json,
                          const std::string& nc_program, const interp::MachineProfile* profile) {
  ControlLoad load;
  load.files = {{prefix + program + ".SPF", "NC program"},
                {prefix + program + "_RESET.SPF", "its reset program"},
                {prefix + plc_csv, "PLC table: the same setting data per trigger position"},
                {prefix + plan_json, "plan document (JSON): for the record, not for the control"}};
  load.prerequisites = NcPrerequisites(nc_program);
  if (profile)
    for (auto& line : ProfilePrerequisites(*profile)) load.prerequisites.push_back(line);
  load.call_order = "call " + program +
                    " before the cutting block, with the axis before the thread start; call " +
                    program + "_RESET after the cutting block.";
  load.after_abort = "call " + program +
                     "_RESET (it cancels the actions and writes back the setting data found "
                     "before the cut), move the axis before the thread start and cut the whole "
                     "thread again: there is no resume from mid-thread.";
  return load;
}

std::string ControlBoxHtml(const std::vector<ControlLoad>& loads) {
  std::string h =
      "<section class='control' id='load'>\n<h2>Load onto the control</h2>\n"
      "<p class='small'>What to take to the SINUMERIK 840D. The links open the files written "
      "with this report. The programs were not run on a real control here: check the sign once "
      "with a constant SD43900 test value and a dial gauge before the first cut.</p>\n";
  for (const ControlLoad& load : loads) h += LoadHtml(load);
  return h + "</section>\n";
}

}  // namespace whirl::compare
