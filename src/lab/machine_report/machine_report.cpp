// Report of one screw cut on a drifting machine (machine_report.h): the "load onto the control"
// box, lead deviation per strategy, sensor plots, how the programs share the setting data. User
// strings (sensor and screw names) reach gnuplot only through GnuplotString (terminal noenhanced)
// and HTML only through HtmlEscape; gnuplot runs through RunProgram with an argument vector.
#include "machine_report/machine_report.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <optional>
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
#include "machine_report/machine_nc.h"
#include "plan/load.h"

namespace whirl::machine_report {
namespace {

namespace fs = std::filesystem;
using machine_eval::kMachineStrategyCount;
using machine_eval::MachineStrategy;
using machine_eval::ReportScrew;

// The terminal of every plot: `height_px` tall (the sensor plot grows with its panels).
std::string Terminal(int height_px) {
  return "set terminal pngcairo size 1000," + std::to_string(height_px) +
         " font 'Sans,10' noenhanced\n";
}

std::string LeadCsv(const ReportScrew& d) {
  std::ostringstream out;
  out << "position_mm";
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    out << ',' << machine_eval::ToString(static_cast<MachineStrategy>(k)) << "_um";
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

// The strategies of each panel of the lead plot: the workpiece rows (none, the history rules,
// the network's plan), then none and workpiece again beside the rows with a machine half, so no
// panel holds more than eight lines.
std::vector<std::vector<std::size_t>> LeadPanels() {
  using S = MachineStrategy;
  const auto at = [](S s) { return static_cast<std::size_t>(s); };
  std::vector<std::vector<std::size_t>> panels(3);
  for (S s : {S::kNone, S::kTraditional, S::kWorkpiece, S::kClass, S::kTable, S::kNearest})
    panels[0].push_back(at(s));
  for (S s : {S::kNone, S::kWorkpiece, S::kWarmup, S::kSchedule, S::kLeadSlope, S::kMachineShop,
              S::kBothShop, S::kBothShopMonitor})
    panels[1].push_back(at(s));
  // The grey box beside the rows it is measured against.
  for (S s : {S::kNone, S::kWorkpiece, S::kWarmup, S::kBothShop, S::kBothGrey})
    panels[2].push_back(at(s));
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
      const std::string name = machine_eval::ToString(static_cast<MachineStrategy>(panel[j]));
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
  return s.empty() ? "(none: the model reads only the control's duty signals)" : s;
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
  plan::ControlLoad load;
  load.heading = screw_name;
  load.plan = p.plan;
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
      "WHIRL_DRIFT_COMP once at power-on (it keeps running all day; the model's rises count "
      "from its start), then WHIRL_TEMP_COMP before each cutting block with the axis before "
      "the thread start; WHIRL_TEMP_COMP_RESET after the cutting block; "
      "WHIRL_DRIFT_COMP_RESET to stop the drift action.";
  load.after_abort =
      "call WHIRL_TEMP_COMP_RESET (it cancels the plan's actions and sets its "
      "hand-over values to 0; the drift action goes on compensating the machine "
      "alone), move the axis before the thread start and cut the whole thread "
      "again with WHIRL_TEMP_COMP. WHIRL_DRIFT_COMP refuses to start while a "
      "plan's compensation is active: call WHIRL_TEMP_COMP_RESET first.";
  load.requirements = p.requirements;
  return compare::ControlBoxHtml({load});
}

std::string ProgramsHtml(const CombinedPrograms* p, const std::string& note) {
  if (!p) return note.empty() ? "" : "<p class='warn'>" + HtmlEscape(note) + "</p>";
  const interp::DriftActionOptions& d = p->drift;
  return "<h2>How the two programs share the setting data</h2><p>The workpiece plan (" +
         std::to_string(p->plan.segments.size()) +
         " segments of the network's curve) hands K0_w, S_w and P_w over; the machine drift action "
         "(the sensor model's offset and slope channels, evaluated every interpolation cycle from "
         "the analog inputs: sensors and the control's duty signals) writes SD43920 = P_w, SD43910 "
         "= S_w + S_m, SD43900 = K0_w + K_m + S_m "
         "(P_w - P_b), the fixed bearing at P_b = " +
         FormatFixed(d.slope_fixed_end_mm, 4) + " mm (MCS). The drift action's output:</p><pre>" +
         HtmlEscape(OutputAction(p->drift_nc)) + "</pre>";
}

std::string StrategyTable(const machine_eval::MachineEvalScrew& r) {
  std::string h =
      "<table><tr><th>strategy</th><th>within 1000 mm [um]</th><th>over the thread "
      "[um]</th><th>ISO 3408-3 class</th></tr>\n";
  char buf[256];
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    std::snprintf(buf, sizeof buf, "<tr><td>%s</td><td>%.1f</td><td>%.1f</td><td>%s</td></tr>\n",
                  machine_eval::ToString(static_cast<MachineStrategy>(k)).c_str(),
                  r.metrics[k].accumulated_1000_um, r.metrics[k].accumulated_total_um,
                  HtmlEscape(ToString(r.iso[k])).c_str());
    h += buf;
  }
  std::snprintf(buf, sizeof buf,
                "</table><p>Left after both_shop, over the thread: workpiece part %.1f um, "
                "machine part %.1f um.</p>\n",
                r.residual_workpiece_total_um, r.residual_machine_total_um);
  return h + buf +
         "<p class='small'>none: no compensation; traditional: the strongest history rule's plan "
         "(class, table or nearest, chosen on the history); class, table, nearest: each history "
         "rule's plan; workpiece: the network's plan alone. Machine models trained only from the "
         "shop's probe, laser and lead measurements, applied from past control samples: warmup: "
         "workpiece plus a time-since-power-on rule; schedule: workpiece plus a rule on the "
         "control's duty signals; lead_slope: workpiece plus a pitch correction from measured past "
         "screws; machine_shop: the sensor model alone; both_shop: workpiece plus the sensor model "
         "(the programs above); both_shop_monitor: both_shop kept valid by the probe checks at the "
         "set-ups.</p>\n";
}

std::string Html(const ReportScrew& r, const std::string& sensor_img, const std::string& lead_img,
                 const CombinedPrograms* programs, const std::string& programs_note) {
  const machine_eval::MachineEvalScrew& x = r.result;
  return HtmlPageBegin(x.screw.name + ": workpiece and machine drift in one cut (simulated)") +
         (programs ? ControlBox(x.screw.name, *programs) : "") + "<p>Scenario " +
         HtmlEscape(r.scenario) + ", machine " + std::to_string(x.machine) + ", test day " +
         std::to_string(x.day) + ", start type " + HtmlEscape(x.start_type) +
         ".</p><h2>Lead deviation per strategy</h2>" + StrategyTable(x) + lead_img +
         "<h2>Sensors</h2><p>The sensor model (" + HtmlEscape(r.sensors_choice) +
         ", trained from the shop's measurements) reads the sensors drawn thick: " +
         List(r.sensors) + ".</p>" + sensor_img + ProgramsHtml(programs, programs_note) +
         HtmlPageEnd();
}

// The combined programs of the screw for the profile, or the note why there are none.
std::optional<CombinedPrograms> Programs(const ReportScrew& r,
                                         const interp::MachineProfile* profile, std::string* note) {
  if (!profile) {
    *note = "combined 840D programs not written: no machine profile given";
    return std::nullopt;
  }
  try {
    return BuildCombinedPrograms(
        r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm, r.plan_options, r.offset,
        r.slope, r.z_ref_mm, *profile, "network curve of screw " + r.result.screw.name,
        "sensor model (" + r.sensors_choice + ") trained only from shop measurements");
  } catch (const InputError& err) {
    *note = std::string("combined 840D programs not written: ") + err.what();
    return std::nullopt;
  }
}

}  // namespace

MachineReport WriteMachineScrewReport(const std::string& dir, const ReportScrew& screw,
                                      const interp::MachineProfile* profile) {
  const machine_eval::MachineEvalScrew& x = screw.result;
  if (!x.ok) throw InputError("report of screw '" + x.screw.name + "': " + x.error);
  MachineReport report;
  const std::optional<CombinedPrograms> programs = Programs(screw, profile, &report.programs_note);
  OutputDir out(dir, "report directory");
  // The screw's day as the control logged it, in the drift run format, so `whirl drift predict
  // --run sensors.csv` evaluates a machine model on it.
  out.Add(
      "sensors.csv",
      drift::FormatRun(
          screw.log, {"control log of screw " + x.screw.name +
                          "'s day from power-on to the "
                          "end of its cut (simulated field world, src/lab/machine/; scenario " +
                          screw.scenario + ", machine day seed " + std::to_string(x.day_seed) + ")",
                      "temperatures through the control's 5-min input filter; the duty "
                      "signals as the control logs them; time_min since the day's 00:00; the "
                      "cut from " +
                          FormatFixed(screw.cut_start_min, 1) + " to " +
                          FormatFixed(screw.cut_end_min, 1) + " min"}));
  const auto panels = GroupSeries(screw.log.sensor_names, kSensorsPerPanel);
  const std::string sensor_img = Render(
      out, "sensors",
      SensorScript(screw.log, x.screw.name + ": sensors on the control", screw.sensors, panels),
      80 + kPanelHeightPx * static_cast<int>(panels.size()));
  out.Add("lead.csv", LeadCsv(screw));
  const auto lead_panels = LeadPanels();
  const std::string lead_img =
      Render(out, "lead",
             LeadScript(x.screw.name + ": lead deviation", x.screw.thread_length_mm, lead_panels),
             40 + 420 * static_cast<int>(lead_panels.size()));
  if (programs)
    for (const auto& [path, text] : CombinedProgramFiles("", *programs))
      out.Add(path.filename().string(), text);
  out.Add("index.html",
          Html(screw, sensor_img, lead_img, programs ? &*programs : nullptr, report.programs_note));
  out.Commit();
  report.index_html = (fs::path(dir) / "index.html").string();
  report.programs = programs.has_value();
  return report;
}

}  // namespace whirl::machine_report
