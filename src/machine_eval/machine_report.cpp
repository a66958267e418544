// Report of one screw cut on a drifting machine (machine_report.h): the "load onto the control"
// box, lead deviation per strategy, sensor plots, how the programs share the setting data. User
// strings (sensor and screw names) reach gnuplot only through GnuplotString (terminal noenhanced)
// and HTML only through HtmlEscape; gnuplot runs through RunProgram with an argument vector.
#include "machine_eval/machine_report.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <sstream>

#include "compare/control_box.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/html_page.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/plot_style.h"
#include "core/run_program.h"
#include "core/safe_text.h"

namespace whirl::machine_eval {
namespace {

namespace fs = std::filesystem;

// The terminal of every plot: `height_px` tall (the sensor plot grows with its panels).
std::string Terminal(int height_px) {
  return "set terminal pngcairo size 1000," + std::to_string(height_px) +
         " font 'Sans,10' noenhanced\n";
}

std::string LeadCsv(const MachineScrewDetail& d) {
  std::ostringstream out;
  out << "position_mm";
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    out << ',' << ToString(static_cast<MachineStrategy>(k)) << "_um";
  out << '\n';
  const std::size_t n = d.leads[0].size();
  for (std::size_t i = 0; i < n; i += 10) {  // every 10th sample: the curves are smooth
    out << d.leads[0].position_mm[i];
    for (const auto& l : d.leads) out << ',' << l.deviation_um[i];
    out << '\n';
  }
  return out.str();
}

constexpr std::size_t kSensorsPerPanel = 8;  // more lines than this in one plot are unreadable
constexpr int kPanelHeightPx = 300;

// The sensor log in panels of at most kSensorsPerPanel lines, related sensors together
// (core/plot_style.h GroupSeries); the machine models' chosen sensors drawn thick.
std::string SensorScript(const drift::Run& log, const std::string& title,
                         const std::vector<std::string>& chosen,
                         const std::vector<std::vector<std::size_t>>& panels) {
  std::string gp =
      "set datafile separator ','\nset key outside right\nset grid\n"
      "set ylabel 'temperature [degC]'\n"
      "set lmargin at screen 0.08\nset rmargin at screen 0.76\nset multiplot layout " +
      std::to_string(panels.size()) + ",1 title " + GnuplotString(title) + "\n";
  for (std::size_t p = 0; p < panels.size(); ++p) {
    gp += p + 1 == panels.size() ? "set xlabel 'time [min]'\n" : "unset xlabel\n";
    gp += "plot ";
    for (std::size_t j = 0; j < panels[p].size(); ++j) {
      const std::string& name = log.sensor_names[panels[p][j]];
      const bool model = std::find(chosen.begin(), chosen.end(), name) != chosen.end();
      gp += (j ? ", " : "") + std::string("'sensors.csv' using 1:") +
            std::to_string(panels[p][j] + 2) + " with lines lc rgb '" +
            std::string(SeriesPalette()[j % SeriesPalette().size()]) + "' lw " +
            (model ? "3.5" : "1.5") + " title " + GnuplotString(name);
    }
    gp += "\n";
  }
  return gp + "unset multiplot\n";
}

// The strategies of each panel of the lead plot: the evaluation's first rows (up to
// both_monitor), then none and both again beside the shop's rows, so no panel holds 14 lines.
std::vector<std::vector<std::size_t>> LeadPanels() {
  const auto last_first = static_cast<std::size_t>(MachineStrategy::kBothMonitor);
  std::vector<std::vector<std::size_t>> panels(1);
  for (std::size_t k = 0; k <= last_first && k < kMachineStrategyCount; ++k) panels[0].push_back(k);
  if (kMachineStrategyCount > last_first + 1) {
    panels.push_back({static_cast<std::size_t>(MachineStrategy::kNone),
                      static_cast<std::size_t>(MachineStrategy::kBoth)});
    for (std::size_t k = last_first + 1; k < kMachineStrategyCount; ++k) panels[1].push_back(k);
  }
  return panels;
}

// Every strategy in its colour and dash (core/plot_style.h), x from the thread start to its end.
std::string LeadScript(const std::string& title, double thread_length_mm,
                       const std::vector<std::vector<std::size_t>>& panels) {
  std::string gp =
      "set datafile separator ','\nset key outside right\nset grid\n"
      "set xlabel 'position along the thread [mm]'\nset xrange [0:" +
      std::to_string(thread_length_mm) +
      "]\nset ylabel 'travel deviation [um]'\nset lmargin at screen 0.08\n"
      "set rmargin at screen 0.8\nset multiplot layout " +
      std::to_string(panels.size()) + ",1 title " + GnuplotString(title) + "\n";
  for (const auto& panel : panels) {
    gp += "plot ";
    for (std::size_t j = 0; j < panel.size(); ++j) {
      const std::string name = ToString(static_cast<MachineStrategy>(panel[j]));
      gp += (j ? ", " : "") + std::string("'lead.csv' using 1:") + std::to_string(panel[j] + 2) +
            " " + GnuplotWith(name) + " title " + GnuplotString(name);
    }
    gp += "\n";
  }
  return gp + "unset multiplot\n";
}

// Adds <stem>.gp to the report and renders <stem>.png in its staging folder; returns the <img>
// tag or a note.
std::string Render(OutputDir& out, const std::string& stem, const std::string& body,
                   int height_px = 480) {
  out.Add(stem + ".gp",
          Terminal(height_px) + "set output " + GnuplotString(stem + ".png") + "\n" + body);
  if (!ProgramSucceeds({"gnuplot", "--version"}))
    return "<p class='warn'>(gnuplot not found: " + HtmlEscape(stem) + ".gp not rendered)</p>";
  const int rc = out.RunInStaging({"gnuplot", stem + ".gp"}, stem + ".log", {stem + ".png"});
  const fs::path stage = out.Staging();
  std::error_code ec;
  if (rc != 0 || !fs::is_regular_file(stage / (stem + ".png"), ec)) {
    if (fs::is_regular_file(stage / (stem + ".log"), ec)) out.AddStaged(stem + ".log");
    return "<p class='warn'>(gnuplot failed on " + HtmlEscape(stem) + ".gp, see " +
           HtmlEscape(stem) + ".log)</p>";
  }
  out.AddStaged(stem + ".png");
  return HtmlImage(stem + ".png", stem);
}

std::string List(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + HtmlEscape(n);
  return s.empty() ? "(none: no machine model)" : s;
}

// The last static action of the drift program: the one that writes the setting data.
std::string OutputAction(const std::string& drift_nc) {
  const std::size_t begin = drift_nc.rfind("\nIDS=");
  if (begin == std::string::npos) return "";
  const std::size_t end = drift_nc.find('\n', begin + 1);
  return drift_nc.substr(begin + 1, end == std::string::npos ? end : end - begin - 1);
}

// The "load onto the control" box of the combined programs (compare/control_box.h).
std::string ControlBox(const std::string& screw_name, const CombinedPrograms& p) {
  compare::ControlLoad load;
  load.heading = screw_name;
  load.plan = &p.plan;
  const interp::DriftActionOptions& d = p.drift;
  load.plan_note =
      "The plan does not write these into the setting data itself: it hands K0, "
      "SD43910 and SD43920 to the drift action through $AC_PARAM[" +
      std::to_string(d.workpiece_k0_param) + "], [" + std::to_string(d.workpiece_slope_param) +
      "], [" + std::to_string(d.workpiece_slope_param + 1) +
      "], which adds the machine's drift every interpolation cycle and is the only "
      "writer of SD43900-43920.";
  load.files = {{"WHIRL_DRIFT_COMP.SPF", "live machine-drift action"},
                {"WHIRL_DRIFT_COMP_RESET.SPF", "stops it, restores the setting data"},
                {"WHIRL_DRIFT_COMP_PLC.csv", "the drift action as a PLC table"},
                {"WHIRL_TEMP_COMP.SPF", "workpiece plan"},
                {"WHIRL_TEMP_COMP_RESET.SPF", "its reset program"}};
  load.call_order =
      "WHIRL_DRIFT_COMP first (it keeps running), then WHIRL_TEMP_COMP before the "
      "cutting block with the axis before the thread start; WHIRL_TEMP_COMP_RESET "
      "after the cutting block; WHIRL_DRIFT_COMP_RESET to stop the drift action.";
  load.after_abort =
      "call WHIRL_TEMP_COMP_RESET (it cancels the plan's actions and sets its "
      "hand-over values to 0; the drift action goes on compensating the machine "
      "alone), move the axis before the thread start and cut the whole thread "
      "again with WHIRL_TEMP_COMP. WHIRL_DRIFT_COMP refuses to start while a "
      "plan's compensation is active: call WHIRL_TEMP_COMP_RESET first.";
  for (const std::string* nc : {&p.drift_nc, &p.plan_nc})
    for (auto& line : compare::NcPrerequisites(*nc))
      if (std::find(load.prerequisites.begin(), load.prerequisites.end(), line) ==
          load.prerequisites.end())
        load.prerequisites.push_back(line);
  return compare::ControlBoxHtml({load});
}

std::string ProgramsHtml(const CombinedPrograms* p, const std::string& note) {
  if (!p) return note.empty() ? "" : "<p class='warn'>" + HtmlEscape(note) + "</p>";
  const interp::DriftActionOptions& d = p->drift;
  return "<h2>How the two programs share the setting data</h2><p>The workpiece plan (" +
         std::to_string(p->plan.segments.size()) +
         " segments of the network's curve) hands K0_w, S_w and P_w over; the machine drift action "
         "(offset model and Z-screw slope model, evaluated every interpolation cycle from the "
         "analog inputs) writes SD43920 = P_w, SD43910 = S_w + S_m, SD43900 = K0_w + K_m + S_m "
         "(P_w - P_b), the fixed bearing at P_b = " +
         FormatFixed(d.slope_fixed_end_mm, 4) + " mm (MCS). The drift action's output:</p><pre>" +
         HtmlEscape(OutputAction(p->drift_nc)) + "</pre>";
}

std::string StrategyTable(const MachineEvalScrew& r) {
  std::string h =
      "<table><tr><th>strategy</th><th>within 1000 mm [um]</th><th>over the thread "
      "[um]</th><th>ISO 3408-3 class</th></tr>\n";
  char buf[256];
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    std::snprintf(buf, sizeof buf, "<tr><td>%s</td><td>%.1f</td><td>%.1f</td><td>%s</td></tr>\n",
                  ToString(static_cast<MachineStrategy>(k)).c_str(),
                  r.metrics[k].accumulated_1000_um, r.metrics[k].accumulated_total_um,
                  HtmlEscape(ToString(r.iso[k])).c_str());
    h += buf;
  }
  std::snprintf(buf, sizeof buf,
                "</table><p>Left after both, over the thread: workpiece part %.1f um, machine "
                "part %.1f um.</p>\n",
                r.residual_workpiece_total_um, r.residual_machine_total_um);
  return h + buf +
         "<p class='small'>none: no compensation; traditional: the strongest history rule's plan; "
         "workpiece: the network's plan alone; machine: the drift action alone; both: plan and "
         "drift action with the cutting-trained machine model; both_idle: with the idle-trained "
         "model; both_monitor: both, checked and refitted on-line. Shop rows (machine models "
         "trained from probe and laser readings, applied causally): class, table, nearest: the "
         "history rules' plans; warmup: workpiece plus a time-since-power-on rule; schedule: "
         "workpiece plus a control-signal rule; machine_shop: the sensor model alone; both_shop: "
         "workpiece plus machine_shop.</p>\n";
}

std::string Html(const MachineEvalScrew& r, const std::vector<std::string>& cutting,
                 const std::vector<std::string>& idle, const std::string& sensor_img,
                 const std::string& lead_img, const CombinedPrograms* programs,
                 const std::string& programs_note) {
  return HtmlPageBegin(r.screw.name + ": workpiece and machine drift in one cut (simulated)") +
         (programs ? ControlBox(r.screw.name, *programs) : "") +
         "<h2>Lead deviation per strategy</h2>" + StrategyTable(r) + lead_img +
         "<h2>Sensors</h2><p>Chosen sensors of the machine's offset model (thick lines), trained "
         "cutting: " +
         List(cutting) + "; trained idle: " + List(idle) + ".</p>" + sensor_img +
         ProgramsHtml(programs, programs_note) + HtmlPageEnd();
}

}  // namespace

std::string WriteMachineScrewReport(const std::string& dir, const MachineEvalScrew& screw,
                                    const MachineScrewDetail& detail,
                                    const std::vector<std::string>& sensors_cutting,
                                    const std::vector<std::string>& sensors_idle,
                                    const CombinedPrograms* programs,
                                    const std::string& programs_note) {
  if (!screw.ok) throw InputError("report of screw '" + screw.screw.name + "': " + screw.error);
  OutputDir out(dir, "report directory");
  std::string sensor_img = "<p>(no sensor log: the machine does not drift)</p>";
  if (detail.log.samples() > 0) {
    // The screw's log in the drift run format (temperatures and the two error channels), so
    // `whirl drift predict --run sensors.csv` evaluates a machine model on it.
    out.Add("sensors.csv",
            drift::FormatRun(detail.log, {"virtual sensor log of screw " + screw.screw.name +
                                              " during its cut (simulated, src/machine/machine.h; "
                                              "machine day seed " +
                                              std::to_string(screw.day_seed) + ")",
                                          "offset_um: machine drift at the Z screw's fixed end; "
                                          "zscrew_per_1000_um: its growth per 1000 mm (um)"}));
    const auto panels = GroupSeries(detail.log.sensor_names, kSensorsPerPanel);
    std::vector<std::string> chosen = sensors_cutting;
    chosen.insert(chosen.end(), sensors_idle.begin(), sensors_idle.end());
    sensor_img =
        Render(out, "sensors",
               SensorScript(detail.log, screw.screw.name + ": virtual sensors", chosen, panels),
               80 + kPanelHeightPx * static_cast<int>(panels.size()));
  }
  out.Add("lead.csv", LeadCsv(detail));
  const auto lead_panels = LeadPanels();
  const std::string lead_img = Render(
      out, "lead",
      LeadScript(screw.screw.name + ": lead deviation", screw.screw.thread_length_mm, lead_panels),
      40 + 420 * static_cast<int>(lead_panels.size()));
  if (programs)
    for (const auto& [path, text] : CombinedProgramFiles("", *programs))
      out.Add(path.filename().string(), text);
  out.Add("index.html", Html(screw, sensors_cutting, sensors_idle, sensor_img, lead_img, programs,
                             programs_note));
  out.Commit();
  return (fs::path(dir) / "index.html").string();
}

}  // namespace whirl::machine_eval
