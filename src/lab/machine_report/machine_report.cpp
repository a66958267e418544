// Report of one screw cut on a drifting machine (machine_report.h): the "load onto the control"
// box, lead deviation per strategy, sensor plots, how the programs share the setting data, built
// as a report document and rendered by core/report_render.h (which escapes every string).
#include "machine_report/machine_report.h"

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <sstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/plot_style.h"
#include "core/report_render.h"
#include "machine_report/machine_nc.h"
#include "plan/load.h"

namespace whirl::machine_report {
namespace {

namespace fs = std::filesystem;
using machine_eval::kMachineStrategyCount;
using machine_eval::MachineStrategy;
using machine_eval::ReportScrew;

using report::Col;
using report::SeriesKind;

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
report::Figure SensorFigure(const drift::Run& log, const std::string& title,
                            const std::vector<std::string>& chosen) {
  report::Figure f;
  f.stem = "sensors";
  f.alt = title;
  f.title = title;
  for (const auto& panel : GroupSeries(log.sensor_names, kSensorsPerPanel)) {
    report::Panel p;
    p.ylabel = "temperature [degC]";
    for (std::size_t j = 0; j < panel.size(); ++j) {
      const std::string& name = log.sensor_names[panel[j]];
      const bool model = std::find(chosen.begin(), chosen.end(), name) != chosen.end();
      report::Series s;
      s.file = "sensors.csv";
      s.columns = {Col(1), Col(static_cast<int>(panel[j]) + 2)};
      s.colour = std::string(PaletteColour(panel[j]));  // the sensor's own, in every panel
      s.width = model ? 3.5 : 1.5;
      s.title = name;
      p.series.push_back(std::move(s));
    }
    f.panels.push_back(std::move(p));
  }
  if (!f.panels.empty()) f.panels.back().xlabel = "time [min]";
  f.height_px = 80 + kPanelHeightPx * static_cast<int>(std::max<std::size_t>(1, f.panels.size()));
  return f;
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

// Every strategy in its colour and dash (core/plot_style.h), x from the thread start to its end,
// each compensated one with its +-1 sd band (`sd_um`: ReportScrew::sd_um) under the lines.
report::Figure LeadFigure(const std::string& title, double thread_length_mm,
                          const std::array<double, kMachineStrategyCount>& sd_um) {
  report::Figure f;
  f.stem = "lead";
  f.alt = title;
  f.title = title;
  for (const auto& panel : LeadPanels()) {
    report::Panel p;
    p.xlabel = "position along the thread [mm]";
    p.ylabel = "travel deviation [um]";
    p.x = {0, thread_length_mm};
    for (std::size_t k : panel) {
      if (!(sd_um[k] > 0)) continue;
      const std::string name = machine_eval::ToString(static_cast<MachineStrategy>(k));
      const int c = static_cast<int>(k) + 2;
      p.series.push_back(
          report::SdBand("lead.csv", Col(1), c, sd_um[k], name,
                         name + " +- 1 sd (" + FormatDecimals(sd_um[k], 1) + " um)"));
    }
    for (std::size_t k : panel) {
      const std::string name = machine_eval::ToString(static_cast<MachineStrategy>(k));
      p.series.push_back({"lead.csv", -1, {Col(1), Col(static_cast<int>(k) + 2)}, SeriesKind::kLine,
                          name, "", 1.5, false, name});
    }
    f.panels.push_back(std::move(p));
  }
  f.height_px = 40 + 420 * static_cast<int>(f.panels.size());
  return f;
}

std::string List(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s.empty() ? "(none: the model reads only the control's duty signals)" : s;
}

// The last static action of the drift program: the one that writes the setting data.
std::string OutputAction(const std::string& drift_nc) {
  const std::size_t begin = drift_nc.rfind("\nIDS=");
  if (begin == std::string::npos) return "";
  const std::size_t end = drift_nc.find('\n', begin + 1);
  return drift_nc.substr(begin + 1, end == std::string::npos ? end : end - begin - 1);
}

// The "load onto the control" box of the combined programs (plan/load.h LoadBox).
report::Box ControlBox(const std::string& screw_name, const CombinedPrograms& p) {
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
      "writer of SD43900-43920." +
      (d.blank_param >= 0 && p.grey
           ? " At the thread start it also latches the grey box's blank estimate $AC_PARAM[" +
                 std::to_string(d.blank_param) + "] into [" + std::to_string(d.blank_param + 1) +
                 "] for the cut (20 again at the thread end)."
           : std::string());
  load.files = {{"WHIRL_DRIFT_COMP.SPF", "live machine-drift action"},
                {"WHIRL_DRIFT_COMP_RESET.SPF", "stops it, restores the setting data"},
                {"WHIRL_DRIFT_COMP_PLC.csv", "the drift action as a PLC table"},
                {"WHIRL_TEMP_COMP.SPF", "workpiece plan"},
                {"WHIRL_TEMP_COMP_RESET.SPF", "its reset program"}};
  load.call_order =
      std::string(p.grey ? "WHIRL_DRIFT_COMP once at power-on (it keeps running all day; the "
                           "grey box reads absolute temperatures, its lags start from the first "
                           "cycle)"
                         : "WHIRL_DRIFT_COMP once at power-on (it keeps running all day; the "
                           "model's rises count from its start)") +
      ", then WHIRL_TEMP_COMP before each cutting block with the axis before "
      "the thread start; WHIRL_TEMP_COMP_RESET after the cutting block; "
      "WHIRL_DRIFT_COMP_RESET to stop the drift action.";
  load.after_abort =
      "call WHIRL_TEMP_COMP_RESET (it cancels the plan's actions and sets its "
      "hand-over values to 0; the drift action goes on compensating the machine "
      "alone), move the axis before the thread start and cut the whole thread "
      "again with WHIRL_TEMP_COMP. WHIRL_DRIFT_COMP refuses to start while a "
      "plan's compensation is active: call WHIRL_TEMP_COMP_RESET first.";
  load.requirements = p.requirements;
  return plan::LoadBox({load});
}

void AddPrograms(const CombinedPrograms* p, const std::string& note, const std::string& reason,
                 report::Document* doc) {
  if (!p) {
    if (!note.empty()) doc->Say(note, report::Tone::kWarn);
    return;
  }
  const interp::DriftActionOptions& d = p->drift;
  doc->Add(report::Heading{2, "How the two programs share the setting data", ""});
  doc->Say("Machine model of the programs: " + reason + ".");
  if (!note.empty()) doc->Say(note, report::Tone::kWarn);
  const std::string what =
      p->grey ? "the grey box's offset and slope from absolute temperatures (T - 20 degC) and "
                "their lags, the slope intercept, and the blank's estimate the plan latches at the "
                "thread start; evaluated every interpolation cycle from the analog inputs"
              : "the sensor model's offset and slope channels, evaluated every interpolation "
                "cycle from the analog inputs: sensors and the control's duty signals";
  doc->Say("The workpiece plan (" + std::to_string(p->plan.segments.size()) +
           " segments of the network's curve) hands K0_w, S_w and P_w over; the machine drift "
           "action (" +
           what +
           ") writes SD43920 "
           "= P_w, SD43910 = S_w + S_m, SD43900 = K0_w + K_m + S_m (P_w - P_b), the fixed bearing "
           "at P_b = " +
           FormatFixed(d.slope_fixed_end_mm, 4) + " mm (MCS). The drift action's output:");
  doc->Add(report::Preformatted{OutputAction(p->drift_nc)});
}

report::Table StrategyTable(const machine_eval::MachineEvalScrew& r,
                            const std::array<double, kMachineStrategyCount>& sd_um) {
  report::Table t;
  t.series_rows = true;
  t.header = {"strategy", "within 1000 mm [um]", "over the thread [um]", "ISO 3408-3 class",
              "band +-1 sd [um]"};
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    t.rows.push_back({machine_eval::ToString(static_cast<MachineStrategy>(k)),
                      FormatDecimals(r.metrics[k].accumulated_1000_um, 1),
                      FormatDecimals(r.metrics[k].accumulated_total_um, 1), ToString(r.iso[k]),
                      sd_um[k] > 0 ? FormatDecimals(sd_um[k], 1) : "-"});
  return t;
}

void AddStrategyNotes(const machine_eval::MachineEvalScrew& r, report::Document* doc) {
  doc->Say("Left after both_shop, over the thread: workpiece part " +
           FormatDecimals(r.residual_workpiece_total_um, 1) + " um, machine part " +
           FormatDecimals(r.residual_machine_total_um, 1) + " um.");
  doc->Say(
      "none: no compensation; traditional: the strongest history rule's plan (class, table or "
      "nearest, chosen on the history); class, table, nearest: each history rule's plan; "
      "workpiece: the network's plan alone. Machine models trained only from the shop's probe, "
      "laser and lead measurements, applied from past control samples: warmup: workpiece plus a "
      "time-since-power-on rule; schedule: workpiece plus a rule on the control's duty signals; "
      "lead_slope: workpiece plus a pitch correction from measured past screws; machine_shop: "
      "the sensor model alone; both_shop: workpiece plus the sensor model; both_shop_monitor: "
      "both_shop kept valid by the probe checks at the set-ups (drawn thin with open circles: "
      "where it coincides with both_shop, both stay visible); both_grey: workpiece plus the grey "
      "box (absolute temperatures, a slope intercept, the blank latched at the cut start). The "
      "programs above apply both_grey or both_shop, as said under them.",
      report::Tone::kSmall);
  doc->Say(
      "The shaded bands: each strategy's curve +- 1 sd of its compensation, the sd from its "
      "training data only (never from the test days): the network's predictive sd of the "
      "maximum elongation; a history rule's leave-one-out mean relative error on the history "
      "times its plateau; warmup, schedule, the sensor model (also for both_shop_monitor) and "
      "the grey box: their grouped CV RMSE over the shop's records; lead_slope: the sd of the "
      "past screws' slopes over the thread; two halves in quadrature. It is the scale of how far "
      "the compensation may be off, not an interval computed for this lead curve.",
      report::Tone::kSmall);
}

report::Document Page(const ReportScrew& r, const CombinedPrograms* programs,
                      const std::string& programs_note, const std::string& reason) {
  const machine_eval::MachineEvalScrew& x = r.result;
  report::Document doc;
  doc.title = x.screw.name + ": workpiece and machine drift in one cut (simulated)";
  if (programs) doc.Add(ControlBox(x.screw.name, *programs));
  doc.Say("Scenario " + r.scenario + ", machine " + std::to_string(x.machine) + ", test day " +
          std::to_string(x.day) + ", start type " + x.start_type + ".");
  doc.Add(report::Heading{2, "Lead deviation per strategy", ""}).Add(StrategyTable(x, r.sd_um));
  AddStrategyNotes(x, &doc);
  doc.Add(LeadFigure(x.screw.name + ": lead deviation", x.screw.thread_length_mm, r.sd_um));
  doc.Add(report::Heading{2, "Sensors", ""});
  const bool grey = programs && programs->grey;
  const std::vector<std::string> thick = grey ? r.grey.Inputs() : r.sensors;
  doc.Say(grey ? "The grey box (both_grey, trained from the shop's measurements; the programs' "
                 "model) reads the sensors drawn thick: " +
                     List(thick) + "."
               : "The sensor model (" + r.sensors_choice +
                     ", trained from the shop's measurements) reads the sensors drawn thick: " +
                     List(thick) + ".");
  doc.Add(SensorFigure(r.log, x.screw.name + ": sensors on the control", thick));
  AddPrograms(programs, programs_note, reason, &doc);
  return doc;
}

// The combined program's model line for a mixed both_grey screw: at w = 1 the program is the grey
// box's own (GreyMixComponents), so the header does not call it mixed.
std::string MixDescription(const ReportScrew& r) {
  if (r.mix_weight == 1.0)
    return "grey box (both_grey) alone (the short-record mix weighs " + r.mix_rule_name +
           " 0) trained only from shop measurements";
  return "grey box (both_grey) mixed with " + r.mix_rule_name + " (w = " +
         FormatFixed(r.mix_weight, 2) + ") trained only from shop measurements";
}

// The combined programs of the screw for the profile, or the note why there are none: the grey
// box's where the evaluation picked both_grey (ReportScrew::programs_strategy), else, or when
// its programs cannot be written for the profile (said in the note), both_shop's.
std::optional<CombinedPrograms> Programs(const ReportScrew& r,
                                         const interp::MachineProfile* profile, std::string* note,
                                         std::string* reason) {
  *reason = r.programs_reason;
  if (!profile) {
    *note = "combined 840D programs not written: no machine profile given";
    return std::nullopt;
  }
  if (r.programs_strategy == MachineStrategy::kBothGrey) {
    try {
      if (r.mix_applied)  // both_grey's line is grey_short_mix's (w = 1: the grey box's)
        return BuildCombinedMixPrograms(
            r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm, r.plan_options,
            r.grey, r.mix_rule_offset, r.mix_rule_slope, r.mix_weight, *profile,
            "network curve of screw " + r.result.screw.name,
            MixDescription(r));
      return BuildCombinedGreyPrograms(r.predicted_curve, r.kinematics,
                                       r.result.screw.thread_length_mm, r.plan_options, r.grey,
                                       *profile, "network curve of screw " + r.result.screw.name,
                                       "grey box (both_grey) trained only from shop measurements");
    } catch (const InputError& err) {
      *note = std::string("the grey box's programs could not be written (") + err.what() +
              "): both_shop's instead";
      *reason =
          "both_shop, as the grey box's programs could not be written; the evaluation had "
          "picked " +
          r.programs_reason;
    }
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

// grey_short_mix's drift action (the fourteenth round) where its row was computed, beside the
// grey box's plan (the plan that latches the blank), or the note why not.
std::optional<CombinedPrograms> MixPrograms(const ReportScrew& r,
                                            const interp::MachineProfile* profile,
                                            const CombinedPrograms* programs, std::string* note) {
  if (!r.mix_computed || r.mix_applied || !profile) return std::nullopt;  // applied: the programs
  if (!programs || !programs->grey) {
    *note =
        "grey_short_mix's drift action not written: the report's programs are not the grey "
        "box's (the mix runs beside the grey box's plan, which latches the blank)";
    return std::nullopt;
  }
  interp::MachineProfile p = *profile;
  p.drift->program_name = kMixDriftProgramName;
  p.drift->reset_program_name = kMixDriftResetProgramName;
  try {
    return BuildCombinedMixPrograms(
        r.predicted_curve, r.kinematics, r.result.screw.thread_length_mm, r.plan_options, r.grey,
        r.mix_rule_offset, r.mix_rule_slope, r.mix_weight, p,
        "network curve of screw " + r.result.screw.name,
        "grey_short_mix (the grey box and " + r.mix_rule_name +
            ") trained only from shop measurements");
  } catch (const InputError& err) {
    *note = std::string("grey_short_mix's drift action could not be written (") + err.what() + ")";
    return std::nullopt;
  }
}

// The page's paragraph on the mix's drift action: its weight, files and what it needs.
void AddMixPrograms(const ReportScrew& r, const CombinedPrograms& mix, report::Document* doc) {
  std::string needs;
  for (const interp::ControlRequirement& q : mix.requirements)
    if (q.datum.rfind("MD28250", 0) == 0 || q.datum.rfind("MD28254", 0) == 0)
      needs += (needs.empty() ? "" : "; ") + q.datum + " >= " + FormatFixed(q.value, 0);
  doc->Add(report::Heading{2, "grey_short_mix on the control (opt-in row)", ""});
  doc->Say("The line w grey box + (1 - w) " + r.mix_rule_name + ", w = " +
           FormatFixed(r.mix_weight, 2) + (mix.mixed ? "" : " (the grey box's line itself)") +
           ": " + kMixDriftProgramName + ".SPF (reset " + kMixDriftResetProgramName +
           ".SPF, PLC table " + kMixDriftProgramName +
           "_PLC.csv) runs in place of WHIRL_DRIFT_COMP.SPF with the same plan, IDs and slots. " +
           "Both programs together: " + needs + ".");
}

}  // namespace

MachineReport WriteMachineScrewReport(const std::string& dir, const ReportScrew& screw,
                                      const interp::MachineProfile* profile) {
  const machine_eval::MachineEvalScrew& x = screw.result;
  if (!x.ok) throw InputError("report of screw '" + x.screw.name + "': " + x.error);
  MachineReport report;
  const std::optional<CombinedPrograms> programs =
      Programs(screw, profile, &report.programs_note, &report.programs_reason);
  const std::optional<CombinedPrograms> mix =
      MixPrograms(screw, profile, programs ? &*programs : nullptr, &report.mix_note);
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
  out.Add("lead.csv", LeadCsv(screw));
  if (programs)
    for (const auto& [path, text] : CombinedProgramFiles("", *programs))
      out.Add(path.filename().string(), text);
  if (mix)
    for (const auto& [path, text] : MixDriftProgramFiles("", *mix))
      out.Add(path.filename().string(), text);
  report::Document page =
      Page(screw, programs ? &*programs : nullptr, report.programs_note, report.programs_reason);
  if (mix) AddMixPrograms(screw, *mix, &page);
  report::RenderReport(page, out);
  out.Commit();
  report.index_html = (fs::path(dir) / "index.html").string();
  report.programs = programs.has_value();
  report.programs_grey = programs && programs->grey;
  report.mix_programs = mix.has_value();
  return report;
}

}  // namespace whirl::machine_report
