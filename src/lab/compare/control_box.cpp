#include "compare/control_box.h"

#include <algorithm>
#include <sstream>

#include "core/html_page.h"
#include "core/numbers.h"
#include "core/safe_text.h"

namespace whirl::compare {
namespace {

// The plan's setting data, one row per segment, and the restoring row at the thread end.
// Positions in machine coordinates or, for a plan made without a machine profile, from the
// thread start.
std::string SettingDataTable(const interp::CompensationPlan& plan, bool machine_coordinates) {
  const std::string unit = machine_coordinates ? "[mm, MCS]" : "[mm from the thread start]";
  std::ostringstream h;
  h << "<table><tr><th>segment</th><th>written when " << HtmlEscape(plan.options.axis)
    << " passes " << unit << "</th><th>SD43900 K0 [mm]</th><th>SD43910 slope [-]</th>"
    << "<th>SD43920 reference " << unit << "</th></tr>\n";
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

std::string LoadHtml(const plan::ControlLoad& load) {
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
  h << "<p><b>Setting data the plan writes</b> (axis " << HtmlEscape(load.plan.options.axis)
    << ", sign " << interp::ToString(load.plan.options.sign) << "):</p>\n"
    << SettingDataTable(load.plan, load.machine_coordinates);
  if (!load.plan_note.empty()) h << "<p class='small'>" << HtmlEscape(load.plan_note) << "</p>\n";
  std::vector<std::string> needs;
  for (const interp::ControlRequirement& r : load.requirements) needs.push_back(ToString(r));
  if (!load.profile_note.empty()) needs.push_back(load.profile_note);
  if (!needs.empty())
    h << "<p><b>Machine data the programs need</b> (check once on the control):</p>\n"
      << Items(needs);
  if (!load.after_abort.empty())
    h << "<p><b>After an aborted cut:</b> " << HtmlEscape(load.after_abort) << "</p>\n";
  return h.str();
}

}  // namespace

std::string ControlBoxHtml(const std::vector<plan::ControlLoad>& loads) {
  std::string h =
      "<section class='control' id='load'>\n<h2>Load onto the control</h2>\n"
      "<p class='small'>What to take to the SINUMERIK 840D. The links open the files written "
      "with this report. The programs were not run on a real control here: check the sign once "
      "with a constant SD43900 test value and a dial gauge before the first cut.</p>\n";
  for (const plan::ControlLoad& load : loads) h += LoadHtml(load);
  return h + "</section>\n";
}

}  // namespace whirl::compare
