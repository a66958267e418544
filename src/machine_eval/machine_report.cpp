// Report of one screw cut on a drifting machine (machine_report.h): sensor plot, chosen
// sensors, lead deviation per strategy. User strings (sensor and screw names) reach gnuplot only
// through GnuplotString (terminal noenhanced) and HTML only through HtmlEscape; gnuplot runs
// through RunProgram with an argument vector.
#include "machine_eval/machine_report.h"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/run_program.h"
#include "core/safe_text.h"

namespace whirl::machine_eval {
namespace {

namespace fs = std::filesystem;

const char* kTerminal = "set terminal pngcairo size 1000,480 font 'Sans,10' noenhanced\n";

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

std::string SensorScript(const drift::Run& log, const std::string& title) {
  std::string gp =
      "set datafile separator ','\nset key outside right\nset grid\n"
      "set xlabel 'time [min]'\nset ylabel 'temperature [degC]'\nset title " +
      GnuplotString(title) + "\nplot ";
  for (std::size_t s = 0; s < log.sensor_names.size(); ++s)
    gp += (s ? ", " : "") + std::string("'sensors.csv' using 1:") + std::to_string(s + 2) +
          " with lines dt " + std::to_string(s / 8 + 1) + " title " +
          GnuplotString(log.sensor_names[s]);  // 8 colours, then dashes
  return gp + "\n";
}

std::string LeadScript(const std::string& title) {
  std::string gp =
      "set datafile separator ','\nset key outside right\nset grid\n"
      "set xlabel 'position along the thread [mm]'\n"
      "set ylabel 'travel deviation [um]'\nset title " +
      GnuplotString(title) + "\nplot ";
  // The variants of 'both' are dashed, so 'both' stays visible where they coincide with it.
  const auto both = static_cast<std::size_t>(MachineStrategy::kBoth);
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    gp += (k ? ", " : "") + std::string("'lead.csv' using 1:") + std::to_string(k + 2) +
          " with lines lw 2" + (k > both ? " dt " + std::to_string(k - both + 1) : "") + " title " +
          GnuplotString(ToString(static_cast<MachineStrategy>(k)));
  return gp + "\n";
}

// Adds <stem>.gp to the report and renders <stem>.png in its staging folder; returns the <img>
// tag or a note.
std::string Render(OutputDir& out, const std::string& stem, const std::string& body) {
  out.Add(stem + ".gp",
          std::string(kTerminal) + "set output " + GnuplotString(stem + ".png") + "\n" + body);
  if (!ProgramSucceeds({"gnuplot", "--version"}))
    return "<p>(gnuplot not found: " + HtmlEscape(stem) + ".gp not rendered)</p>";
  const fs::path stage = fs::absolute(out.Staging());
  const int rc = RunProgram({"gnuplot", stem + ".gp"}, stage, stage / (stem + ".log"));
  std::error_code ec;
  if (rc != 0 || !fs::is_regular_file(stage / (stem + ".png"), ec)) {
    if (fs::is_regular_file(stage / (stem + ".log"), ec)) out.AddStaged(stem + ".log");
    return "<p>(gnuplot failed on " + HtmlEscape(stem) + ".gp, see " + HtmlEscape(stem) +
           ".log)</p>";
  }
  out.AddStaged(stem + ".png");
  return "<img src='" + HtmlEscape(stem + ".png") + "' alt='" + HtmlEscape(stem) + "'>";
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

std::string ProgramsHtml(const CombinedPrograms* p, const std::string& note) {
  if (!p) return note.empty() ? "" : "<p>" + HtmlEscape(note) + "</p>";
  const interp::DriftActionOptions& d = p->drift;
  std::string h =
      "<h2>Combined 840D programs (one writer per setting datum)</h2><p>The workpiece plan (" +
      std::to_string(p->plan.segments.size()) +
      " segments of the network's curve) writes its K0, SD43910 and SD43920 into $AC_PARAM[" +
      std::to_string(d.workpiece_k0_param) + "], [" + std::to_string(d.workpiece_slope_param) +
      "], [" + std::to_string(d.workpiece_slope_param + 1) +
      "]; the machine drift action (offset model and Z-screw slope model, evaluated every "
      "interpolation cycle from the analog inputs) is the only writer of SD43900-43920: "
      "SD43920 = P_w, SD43910 = S_w + S_m, SD43900 = K0_w + K_m + S_m (P_w - P_b), the fixed "
      "bearing at P_b = " +
      FormatFixed(d.slope_fixed_end_mm, 4) +
      " mm (MCS). Call WHIRL_DRIFT_COMP first, then WHIRL_TEMP_COMP before the cutting block, "
      "the reset programs after the cut or an abort.</p><ul>";
  for (const char* f : {"WHIRL_TEMP_COMP.SPF", "WHIRL_TEMP_COMP_RESET.SPF", "WHIRL_DRIFT_COMP.SPF",
                        "WHIRL_DRIFT_COMP_RESET.SPF", "WHIRL_DRIFT_COMP_PLC.csv"})
    h += std::string("<li><a href='") + f + "'>" + f + "</a></li>";
  return h + "</ul><p>The drift action's output:</p><pre>" + HtmlEscape(OutputAction(p->drift_nc)) +
         "</pre>";
}

std::string Html(const MachineEvalScrew& r, const std::vector<std::string>& cutting,
                 const std::vector<std::string>& idle, const std::string& sensor_img,
                 const std::string& lead_img, const CombinedPrograms* programs,
                 const std::string& programs_note) {
  std::string h = "<!doctype html><html><head><meta charset='utf-8'><title>" +
                  HtmlEscape(r.screw.name) + ": both halves</title></head><body><h1>" +
                  HtmlEscape(r.screw.name) +
                  ": workpiece and machine drift in one cut (simulated)</h1>"
                  "<p>Chosen sensors of the machine's offset model, trained cutting: " +
                  List(cutting) + "; trained idle: " + List(idle) + ".</p><h2>Sensors</h2>" +
                  sensor_img + "<h2>Lead deviation per strategy</h2>" + lead_img +
                  "<table border='1' cellpadding='4'><tr><th>strategy</th><th>within 1000 mm "
                  "[um]</th><th>over the thread [um]</th><th>ISO class</th></tr>";
  char buf[256];
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    std::snprintf(buf, sizeof buf, "<tr><td>%s</td><td>%.1f</td><td>%.1f</td><td>%s</td></tr>",
                  ToString(static_cast<MachineStrategy>(k)).c_str(),
                  r.metrics[k].accumulated_1000_um, r.metrics[k].accumulated_total_um,
                  HtmlEscape(ToString(r.iso[k])).c_str());
    h += buf;
  }
  std::snprintf(buf, sizeof buf,
                "</table><p>Left after both, over the thread: workpiece part %.1f um, machine "
                "part %.1f um.</p>",
                r.residual_workpiece_total_um, r.residual_machine_total_um);
  return h + buf + ProgramsHtml(programs, programs_note) + "</body></html>\n";
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
    sensor_img =
        Render(out, "sensors", SensorScript(detail.log, screw.screw.name + ": virtual sensors"));
  }
  out.Add("lead.csv", LeadCsv(detail));
  const std::string lead_img =
      Render(out, "lead", LeadScript(screw.screw.name + ": lead deviation"));
  if (programs)
    for (const auto& [path, text] : CombinedProgramFiles("", *programs))
      out.Add(path.filename().string(), text);
  out.Add("index.html", Html(screw, sensors_cutting, sensors_idle, sensor_img, lead_img, programs,
                             programs_note));
  out.Commit();
  return (fs::path(dir) / "index.html").string();
}

}  // namespace whirl::machine_eval
