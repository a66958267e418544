#include "compare/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "compare/control_box.h"
#include "core/csv.h"
#include "core/html_page.h"
#include "core/json_file.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/plot_style.h"
#include "core/run_program.h"
#include "core/safe_text.h"

namespace whirl::compare {
namespace {

std::string Pct(const std::optional<double>& v) { return v ? FormatDecimals(*v, 1) + " %" : "-"; }

std::vector<std::string> Comments(const ReportOptions& o, const std::string& what) {
  std::vector<std::string> c{" " + what};
  for (const auto& p : o.provenance) c.push_back(" " + p);
  return c;
}

bool HaveGnuplot(const std::string& command) {
  return !command.empty() && ProgramSucceeds({command, "--version"});
}

std::string Terminal(const std::string& command) {
  const bool cairo = ProgramSucceeds({command, "-e", "set terminal pngcairo"});
  return cairo ? "pngcairo size 1000,560 font 'Sans,11' noenhanced"
               : "png size 1000,560 noenhanced";
}

struct PlotFiles {
  std::string elongation, lead, lead_start;
};

// The legend's words for a strategy (the tables use the bare names); `model_family` names the
// model's family (workpiece::WorkpieceModel::FamilyLabel).
std::string StrategyLabel(Strategy s, const std::string& model_family) {
  switch (s) {
    case Strategy::kNone:
      return "none (no compensation)";
    case Strategy::kRamp:
      return "ramp (old rule: class plateau ramped in)";
    case Strategy::kTraditional:
      return "traditional (strongest history rule, 840D plan)";
    case Strategy::kRegression:
      return "regression (log-linear features, 840D plan)";
    case Strategy::kModel:
      return "model (" + model_family + ", 840D plan)";
    case Strategy::kClass:
      return "class (diameter-class means, 840D plan)";
    case Strategy::kTable:
      return "table (experience table, 840D plan)";
    case Strategy::kNearest:
      return "nearest (3 nearest past screws, 840D plan)";
  }
  return ToString(s);
}

// The strategies that compensate (all but none), in kStrategies order: the elongation plot's
// compensation columns.
std::vector<Strategy> CompensatingStrategies() {
  std::vector<Strategy> out;
  for (Strategy s : kStrategies)
    if (s != Strategy::kNone) out.push_back(s);
  return out;
}

// The +-1 sd band of the predicted curve: the arctangent curves of (L - sd_L, t_s + sd_t) and
// (L + sd_L, t_s - sd_t), the two corners that move the whole curve down and up (l(t) grows with L
// and falls with t_s); t_s stays at least 1 s.
std::pair<fit::ArctanCurve, fit::ArctanCurve> PredictionBand(const ScrewComparison& c) {
  const Features& m = c.prediction.mean;
  const Features& sd = c.prediction.stddev;
  const fit::ArctanCurve& p = c.predicted_curve;
  auto curve = [&p](double l_um, double t_s) {
    return fit::ArctanCurve::FromFeatures({std::max(0.0, l_um), std::max(1.0, t_s)}, p.shape_k,
                                          p.time_exponent);
  };
  return {curve(m.max_elongation_um - sd.max_elongation_um, m.settle_time_s + sd.settle_time_s),
          curve(m.max_elongation_um + sd.max_elongation_um, m.settle_time_s - sd.settle_time_s)};
}

// Elongation: the truth, the prediction with its band, each strategy's compensation, the plan's
// points. Columns of <slug>_elongation.csv: see AddScrewData.
std::string ElongationPlot(const ScrewComparison& c, const std::string& slug,
                           const std::string& png) {
  const double t_end = c.truth.time_s.back();
  const double settle = std::max(c.predicted_curve.settle_time_s, c.experience_ramp_time_s);
  const double t_zoom = std::min(t_end, std::max(60.0, 3.0 * settle));
  std::ostringstream s;
  s << "set output " << GnuplotString(png) << "\nset key right bottom box opaque\n"
    << "set title "
    << GnuplotString(c.screw.name + ": elongation of the unmachined section (first " +
                     FormatDecimals(t_zoom, 0) + " s of " + FormatDecimals(t_end, 0) +
                     " s cutting time)")
    << " noenhanced\nset xlabel 'cutting time t [s]'\nset ylabel 'elongation [um]'\n"
    << "set xrange [0:" << t_zoom << "]\nset yrange [0:*]\n"
    << "plot " << GnuplotString(slug + "_elongation.csv")
    << " using 1:4:5 with filledcurves fs transparent solid 0.15 noborder lc rgb '"
    << FindSeriesStyle("prediction")->colour << "' title 'prediction +- 1 sd', \\\n"
    << "  '' using 1:3 " << GnuplotWith("prediction")
    << " title 'predicted arctan curve (model)', \\\n"
    << "  '' using 1:2 " << GnuplotWith("measured") << " title 'simulated truth (disturbed)'";
  int column = 6;
  for (Strategy st : CompensatingStrategies())
    s << ", \\\n  '' using 1:" << column++ << " " << GnuplotWith(ToString(st)) << " title "
      << GnuplotString("compensation: " + StrategyLabel(st, c.model_family));
  s << ", \\\n  " << GnuplotString(slug + "_points.csv")
    << " using 1:3 with points pt 7 ps 0.8 lc rgb '#000000' title 'SD43900/10/20 breakpoints "
       "(model plan)'\nset output\n";
  return s.str();
}

// Travel deviation of every strategy along the thread (x from 0 to `x_end_mm`).
std::string LeadPlot(const ScrewComparison& c, const std::string& slug, const std::string& png,
                     double x_end_mm, const std::string& title) {
  std::ostringstream s;
  // The key below in two columns: room for its rows, the x label and the tick labels. gnuplot
  // overestimates the width of pngcairo's text, so two columns of the long labels ran past the
  // picture's right edge; "width -8" takes 8 characters off each column.
  s << "set key below horizontal box maxcols 2 width -8\nset bmargin "
    << (c.outcomes.size() + 1) / 2 + 5
    << "\nset output " << GnuplotString(png) << "\nset title "
    << GnuplotString(c.screw.name + ": " + title) << " noenhanced\n"
    << "set xlabel 'position from the thread start [mm]'\nset ylabel 'travel deviation [um]'\n"
    << "set xrange [0:" << x_end_mm << "]\nset yrange [*:*]\nplot ";
  for (std::size_t k = 0; k < c.outcomes.size(); ++k)
    s << (k ? ", \\\n  '' " : GnuplotString(slug + "_lead.csv") + " ") << "using 1:" << k + 2 << " "
      << GnuplotWith(ToString(c.outcomes[k].strategy)) << " title "
      << GnuplotString(StrategyLabel(c.outcomes[k].strategy, c.model_family));
  s << "\nset output\n";
  return s.str();
}

// The gnuplot script for one screw: reads the CSVs and writes the PNGs beside it.
std::string GnuplotScript(const ScrewComparison& c, const std::string& slug, const PlotFiles& f,
                          const std::string& terminal) {
  const double l = c.screw.thread_length_mm;
  return "# gnuplot script written by whirl; re-run with: gnuplot " + slug + ".gp\n" +
         "set datafile separator ','\nset datafile commentschars '#'\nset terminal " + terminal +
         "\nset grid\n" + ElongationPlot(c, slug, f.elongation) +
         LeadPlot(c, slug, f.lead, l,
                  "travel deviation along the thread after cooling (actual - specified)") +
         LeadPlot(c, slug, f.lead_start, std::min(l, 1000.0),
                  "travel deviation, first " + FormatDecimals(std::min(l, 1000.0), 0) +
                      " mm of the thread");
}

// One row per strategy: the accumulated errors, the ISO 3408-3 figures and class, and how much
// less the model leaves than the strategy.
std::string MetricsTable(const ScrewComparison& c) {
  const auto& m = c.Outcome(Strategy::kModel);
  bool v_2pi = true;
  for (const auto& o : c.outcomes) v_2pi = v_2pi && o.metrics.v_2pi_um.has_value();
  std::ostringstream h;
  h << "<table><tr><th>strategy</th><th>within any 1000 mm [um]</th><th>whole thread [um]</th>"
       "<th>e_a [um]</th><th>v_u [um]</th><th>v_300 [um]</th>"
    << (v_2pi ? "<th>v_2pi [um]</th>" : "")
    << "<th>ISO 3408-3 class</th><th>model vs it, 1000 mm</th><th>model vs it, thread</th></tr>\n";
  for (const auto& o : c.outcomes) {
    const MetricReductions r = Reductions(m.metrics, o.metrics);
    const bool model = o.strategy == Strategy::kModel;
    h << "<tr" << (model ? " class='cls'" : "") << "><td>" << ToString(o.strategy) << "</td><td>"
      << FormatDecimals(o.metrics.accumulated_1000_um, 1) << "</td><td>"
      << FormatDecimals(o.metrics.accumulated_total_um, 1) << "</td><td>"
      << FormatDecimals(o.metrics.e_a_um, 1) << "</td><td>" << FormatDecimals(o.metrics.v_u_um, 1)
      << "</td><td>" << FormatDecimals(o.metrics.v_300_um, 1) << "</td>"
      << (v_2pi ? "<td>" + FormatDecimals(*o.metrics.v_2pi_um, 1) + "</td>" : "") << "<td>"
      << ToString(o.iso.reached) << "</td><td>" << (model ? "" : Pct(r.accumulated_1000_pct))
      << "</td><td>" << (model ? "" : Pct(r.accumulated_total_pct)) << "</td></tr>\n";
  }
  h << "</table>\n<ul class='small'>\n";
  for (const auto& o : c.outcomes)
    h << "<li><b>" << ToString(o.strategy) << "</b>: " << HtmlEscape(o.iso.message) << "</li>\n";
  h << "</ul>\n<p class='small'>none: no compensation; ramp: the class plateau ramped in "
       "linearly over the mean settle time (the previous rule); traditional: the strongest of the "
       "history rules class, table and nearest (chosen by leave-one-out on the history, here "
    << ToString(c.traditional_rule)
    << "); class: diameter-class means; table: the experience table; nearest: the 3 nearest past "
       "screws; regression: log-linear least squares of both features on the five inputs. All "
       "but none and ramp use the model's curve shape and the same 840D planning; model: the "
       "workpiece model, "
    << HtmlEscape(c.model_description) << ". \"model vs it\" = 100 (1 - model / it).</p>\n";
  return h.str();
}

// The screw's data files: <slug>_elongation.csv (time, truth, prediction, its band, then each
// compensating strategy's compensation, in CompensatingStrategies order: the columns the plot
// script reads by number), the plan's compensation points and the travel deviation of each
// strategy (CSV with `options.provenance` as comments).
void AddScrewData(const ScrewComparison& c, const std::string& slug, const ReportOptions& options,
                  OutputDir& out) {
  const auto [low, high] = PredictionBand(c);
  std::vector<std::string> header{"time_s", "truth_elongation_um", "predicted_elongation_um",
                                  "predicted_minus_1sd_um", "predicted_plus_1sd_um"};
  for (Strategy st : CompensatingStrategies()) header.push_back(ToString(st) + "_compensation_um");
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < c.truth.size(); ++i) {
    const double t = c.truth.time_s[i];
    rows.push_back({t, c.truth.elongation_um[i], c.predicted_curve.ElongationUm(t),
                    low.ElongationUm(t), high.ElongationUm(t)});
    for (Strategy st : CompensatingStrategies())
      rows.back().push_back(c.compensation_um[static_cast<std::size_t>(st)][i]);
  }
  out.Add(
      slug + "_elongation.csv",
      FormatCsv(header, rows,
                Comments(options, "elongation of the unmachined section of screw '" + c.screw.name +
                                      "', the prediction +- 1 sd (curves of "
                                      "the features at +-1 sd) and the compensation applied")));
  out.Add(slug + "_points.csv",
          interp::FormatPointsCsv(
              c.plan, Comments(options,
                               "compensation points of the 840D plan (the last row is the "
                               "thread end, where the values found before the cut are "
                               "restored)")));
  header = {"position_mm"};
  for (const auto& o : c.outcomes) header.push_back(ToString(o.strategy) + "_deviation_um");
  rows.clear();
  for (std::size_t i = 0; i < c.outcomes[0].lead.size(); ++i) {
    rows.push_back({c.outcomes[0].lead.position_mm[i]});
    for (const auto& o : c.outcomes) rows.back().push_back(o.lead.deviation_um[i]);
  }
  out.Add(slug + "_lead.csv",
          FormatCsv(header, rows,
                    Comments(options,
                             "travel deviation (actual - specified travel from the "
                             "thread start) of screw '" +
                                 c.screw.name + "'")));
}

// Runs gnuplot on the screw's script in the staging folder (an argument vector, no shell: neither
// the directory nor the names are ever parsed). Returns whether all three plots were rendered
// (they are then added to `out` and to `rendered`); else `warning` says why and gnuplot's log is
// kept.
bool RenderPlots(const ScrewComparison& c, const std::string& slug, const PlotFiles& files,
                 const std::filesystem::path& dir, const ReportOptions& options, OutputDir& out,
                 std::set<std::string>* rendered, std::string* warning) {
  const std::string log = slug + ".gp.log";
  const int rc = out.RunInStaging({options.gnuplot_command, slug + ".gp"}, log,
                                  {files.elongation, files.lead, files.lead_start});
  const std::filesystem::path stage = out.Staging();
  bool ok = rc == 0;
  for (const std::string& png : {files.elongation, files.lead, files.lead_start}) {
    std::error_code ec;
    ok = ok && std::filesystem::is_regular_file(stage / png, ec) &&
         std::filesystem::file_size(stage / png, ec) > 0;
  }
  if (ok) {
    for (const std::string& png : {files.elongation, files.lead, files.lead_start}) {
      out.AddStaged(png);
      rendered->insert(png);
    }
  } else {
    std::error_code ec;
    if (std::filesystem::exists(stage / log, ec)) out.AddStaged(log);
    *warning = "gnuplot failed on " + (dir / (slug + ".gp")).string() + " (see " +
               (dir / (slug + ".gp.log")).string() + "): plots of '" + c.screw.name + "' skipped";
  }
  return ok;
}

// The screw's heading, its inputs and, when the model extrapolates, the inputs outside its domain.
std::string InputsSection(const ScrewComparison& c) {
  std::ostringstream body;
  const auto in = c.screw.process;
  body << "<h2>" << HtmlEscape(c.screw.name) << "</h2>\n<p>Inputs: hardness "
       << FormatDecimals(in.hardness_hrc, 1) << " HRC, diameter "
       << FormatDecimals(in.diameter_mm, 1) << " mm, lead " << FormatDecimals(in.pitch_mm, 2)
       << " mm, raceway radius " << FormatDecimals(in.raceway_radius_mm, 2) << " mm, cutting speed "
       << FormatDecimals(in.cutting_speed_m_min, 0) << " m/min; blank "
       << FormatDecimals(c.screw.length_mm, 0) << " mm, thread "
       << FormatDecimals(c.screw.thread_length_mm, 0) << " mm; axial feed "
       << FormatDecimals(c.kinematics.axial_feed_mm_min, 1) << " mm/min, cutting time "
       << FormatDecimals(c.kinematics.cutting_time_s / 60, 1) << " min.</p>\n";
  if (c.prediction.outside_domain) {
    std::string fields;
    for (const auto& f : c.prediction.outside_domain_fields)
      fields += (fields.empty() ? "" : ", ") + f;
    body << "<p class='warn'>The model extrapolates: outside its training domain in "
         << HtmlEscape(fields) << ".</p>\n";
  }
  return body.str();
}

// The features each strategy works from: the truth's, the model's (+- 1 sd), the ramp's class
// plateau and ramp time, the traditional rule's class means and the regression's.
std::string FeaturesTable(const ScrewComparison& c) {
  std::ostringstream body;
  auto row = [&body](const std::string& what, const std::string& l, const std::string& t) {
    body << "<tr><td>" << what << "</td><td>" << l << "</td><td>" << t << "</td></tr>\n";
  };
  body << "<table><tr><th></th><th>max elongation [um]</th><th>settle time [s]</th></tr>\n";
  row("simulated truth (seed " + std::to_string(c.seed) + ", disturbances " +
          (c.disturbances_on ? "on" : "off") + ")",
      FormatDecimals(c.truth_features.max_elongation_um, 1),
      FormatDecimals(c.truth_features.settle_time_s, 0));
  row("model prediction (+- 1 sd)",
      FormatDecimals(c.prediction.mean.max_elongation_um, 1) + " +- " +
          FormatDecimals(c.prediction.stddev.max_elongation_um, 1),
      FormatDecimals(c.prediction.mean.settle_time_s, 0) + " +- " +
          FormatDecimals(c.prediction.stddev.settle_time_s, 0));
  const std::string cls = "class " + FormatDecimals(c.experience_class.nominal_diameter_mm, 0) +
                          " mm, " + std::to_string(c.experience_class.screws) + " past screws";
  row("ramp (" + cls + ")", FormatDecimals(c.experience_class.plateau_um, 1),
      FormatDecimals(c.experience_ramp_time_s, 0) + " (linear ramp)");
  row("traditional (= " + ToString(c.traditional_rule) + ", chosen on the history)",
      FormatDecimals(c.traditional_features.max_elongation_um, 1),
      FormatDecimals(c.traditional_features.settle_time_s, 0));
  for (std::size_t k = 0; k < kHistoryRuleCount; ++k)
    row(ToString(static_cast<HistoryRule>(k)) +
            (k == 0 ? " (" + cls + ", means)" : std::string(" (history rule)")),
        FormatDecimals(c.history_features[k].max_elongation_um, 1),
        FormatDecimals(c.history_features[k].settle_time_s, 0));
  if (c.regression_features.max_elongation_um > 0)
    row("regression (log-linear on the five inputs)",
        FormatDecimals(c.regression_features.max_elongation_um, 1),
        FormatDecimals(c.regression_features.settle_time_s, 0));
  else
    row("regression", "-", "- (the history has no regression: equals none)");
  body << "</table>\n";
  return body.str();
}

// The disturbances of the truth and the 840D plan's figures.
std::string PlanParagraph(const ScrewComparison& c) {
  std::ostringstream body;
  body << "<p class='small'>Disturbances of the truth (unknown to the model): heat partition x"
       << FormatDecimals(c.disturbances.heat_partition_factor, 3) << ", expansion coefficient x"
       << FormatDecimals(c.disturbances.expansion_factor, 3) << ", ambient drift "
       << FormatDecimals(c.disturbances.ambient_drift_k_per_h, 3)
       << " K/h. 840D plan: " << c.plan.segments.size() << " segments (" << c.plan.point_count
       << " points; uniform spacing would need "
       << (c.plan.uniform_point_count > 0 ? std::to_string(c.plan.uniform_point_count)
                                          : std::string("more than 1000000"))
       << "), max |chord - curve| " << FormatDecimals(c.plan.max_deviation_um, 2)
       << " um, max |SD43910| " << FormatFixed(c.plan.max_abs_slope, interp::kDecimalsSd43910)
       << " (MD32760 cap " << FormatFixed(c.plan.options.md32760, 4) << "), axis "
       << HtmlEscape(c.plan.options.axis) << ", sign " << interp::ToString(c.plan.options.sign)
       << ".</p>\n";
  return body.str();
}

// The screw's HTML section: inputs, the strategies' results, plots (or why not), the features,
// the plan and the data links.
std::string ScrewSection(const ScrewComparison& c, const std::string& slug, const PlotFiles& files,
                         const std::set<std::string>& rendered) {
  std::ostringstream body;
  body << InputsSection(c) << MetricsTable(c);
  for (const std::string& png : {files.elongation, files.lead, files.lead_start}) {
    if (rendered.count(png) > 0)
      body << HtmlImage(png, png) << "\n";
    else
      body << "<p class='warn'>Plot " << HtmlEscape(png) << " not rendered (see warnings).</p>\n";
  }
  body << "<p>Features each strategy works from:</p>\n" << FeaturesTable(c) << PlanParagraph(c);
  body << "<p class='small'>Data: ";
  for (const std::string& f : {slug + "_elongation.csv", slug + "_points.csv", slug + "_lead.csv"})
    body << HtmlLink(f, f) << ", ";
  body << "gnuplot script " << HtmlLink(slug + ".gp", slug + ".gp") << ".</p>\n";
  return body.str();
}

// The box's entries: the caller's (files, prerequisites, ...) with each screw's name and plan, or,
// without them, each plan's setting data and where the programs come from.
std::vector<plan::ControlLoad> ControlLoads(const std::vector<ScrewComparison>& comparisons,
                                            const ReportOptions& options) {
  std::vector<plan::ControlLoad> loads;
  for (std::size_t i = 0; i < comparisons.size(); ++i) {
    plan::ControlLoad load;
    if (i < options.control.size()) {
      load = options.control[i];
    } else {
      load.no_files =
          "this command writes no NC programs; 'whirl plan' writes them for your machine (give "
          "it the model, the screw and the machine profile, see whirl plan --help).";
      load.plan_note =
          "Setting data of this comparison's plan (positions from the thread start, not placed "
          "on a machine's axis by a machine profile): plan for your machine with 'whirl plan'.";
      load.machine_coordinates = false;
    }
    load.heading = comparisons[i].screw.name;
    load.plan = comparisons[i].plan;
    loads.push_back(std::move(load));
  }
  return loads;
}

// How to read the page; the strategies are listed from kStrategies.
std::string HowToRead(const std::string& history, const std::string& model_family) {
  std::string names;
  for (Strategy s : kStrategies)
    names += (names.empty() ? "" : "; ") + StrategyLabel(s, model_family);
  return "<h2>How to read this page</h2>\n<p>Each screw is cut in the simulator (the ground "
         "truth, with seeded disturbances the model never saw) once per strategy: " +
         HtmlEscape(names) +
         ". The curve-based strategies share the model's curve shape and 840D planning; the "
         "history rules (ramp, class, table, nearest, traditional, regression) use the past "
         "screws of " +
         HtmlEscape(history.empty() ? "the history named under the title" : history) +
         ". Travel deviation = actual "
         "minus specified travel from the thread start after cooling; accumulated error within "
         "1000 mm = the largest max - min of the deviation within any 1000 mm of thread (the "
         "paper's figure), over the whole thread = max - min over the thread. e_a, v_u, v_300, "
         "v_2pi as ISO 3408-3 (about the least-squares mean travel line).</p>\n"
         "<p class='small'>ISO 3408-3 caveat: only some tolerance cells are confirmed by a source "
         "(Steinmeyer, HIWIN catalogue); the others are recalled values "
         "(datasets/standards/iso3408_3_lead_tolerances.csv). Treat the class as indicative.</p>\n";
}

// The page: title, provenance, the "load onto the control" box, notes, warnings, the screws'
// sections, how to read it.
std::string IndexHtml(const ReportOptions& options, const std::vector<std::string>& warnings,
                      const std::vector<plan::ControlLoad>& loads, const std::string& sections,
                      const std::string& model_family) {
  std::ostringstream html;
  html << HtmlPageBegin(options.title, options.provenance) << ControlBoxHtml(loads);
  for (const auto& n : options.notes) html << "<p>" << HtmlEscape(n) << "</p>\n";
  for (const auto& w : warnings) html << "<p class='warn'>warning: " << HtmlEscape(w) << "</p>\n";
  html << sections << HowToRead(options.history, model_family) << HtmlPageEnd();
  return html.str();
}

}  // namespace

std::string FormatComparisonTable(const ScrewComparison& c) {
  const auto& m = c.Outcome(Strategy::kModel);
  std::ostringstream s;
  char buf[256];
  std::snprintf(buf, sizeof buf, "  %-12s %14s %14s %8s %8s %8s %10s %14s\n", "strategy",
                "1000 mm [um]", "thread [um]", "e_a", "v_u", "v_300", "ISO class", "model vs it");
  s << buf;
  for (const auto& o : c.outcomes) {
    const auto r = Reductions(m.metrics, o.metrics).accumulated_1000_pct;
    std::snprintf(buf, sizeof buf, "  %-12s %14.2f %14.2f %8.2f %8.2f %8.2f %10s %14s\n",
                  ToString(o.strategy).c_str(), o.metrics.accumulated_1000_um,
                  o.metrics.accumulated_total_um, o.metrics.e_a_um, o.metrics.v_u_um,
                  o.metrics.v_300_um, ToString(o.iso.reached).c_str(),
                  o.strategy == Strategy::kModel ? "" : Pct(r).c_str());
    s << buf;
  }
  s << "  ISO 3408-3 class reached:";
  for (const auto& o : c.outcomes)
    s << " " << ToString(o.strategy) << " " << ToString(o.iso.reached);
  s << "\n";
  return s.str();
}

std::string Slug(const std::string& name) {
  constexpr std::size_t kMaxLength = 64;  // file names stay far below NAME_MAX (255)
  std::string s;
  for (char ch : name) {
    if (s.size() >= kMaxLength) break;
    const unsigned char u = static_cast<unsigned char>(ch);
    if (std::isalnum(u))
      s += static_cast<char>(std::tolower(u));
    else if (ch == '-' || ch == '_')
      s += ch;
    else if (!s.empty() && s.back() != '-')
      s += '-';
  }
  while (!s.empty() && s.back() == '-') s.pop_back();
  return s.empty() ? "screw" : s;
}

ReportResult WriteReport(const std::filesystem::path& dir,
                         const std::vector<ScrewComparison>& comparisons,
                         const ReportOptions& options) {
  // Everything is collected in memory (gnuplot renders in the directory's staging folder), then
  // committed all-or-nothing; files of an earlier report that this one does not write (a PNG now
  // "not rendered") are removed (core/output_dir.h).
  OutputDir out(dir, "report directory");
  ReportResult result;
  const bool gnuplot = options.plots && HaveGnuplot(options.gnuplot_command);
  if (options.plots && !gnuplot)
    result.warnings.push_back("'" + options.gnuplot_command +
                              "' not found: plots skipped (install gnuplot-nox, e.g. "
                              "scripts/setup.sh); the HTML, CSV data and .gp scripts are written");
  const std::string terminal = gnuplot ? Terminal(options.gnuplot_command) : "pngcairo";
  bool all_rendered = gnuplot;
  std::set<std::string> rendered;

  std::vector<std::string> slugs;
  nlohmann::json report_json = nlohmann::json::array();
  std::ostringstream body;
  for (const ScrewComparison& c : comparisons) {
    std::string slug = Slug(c.screw.name);
    while (std::find(slugs.begin(), slugs.end(), slug) != slugs.end()) slug += "_";
    slugs.push_back(slug);

    AddScrewData(c, slug, options, out);
    const PlotFiles files{slug + "_elongation.png", slug + "_lead.png", slug + "_lead_start.png"};
    out.Add(slug + ".gp", GnuplotScript(c, slug, files, terminal));
    std::string warning;
    if (gnuplot && !RenderPlots(c, slug, files, dir, options, out, &rendered, &warning)) {
      all_rendered = false;
      result.warnings.push_back(warning);
    }
    body << ScrewSection(c, slug, files, rendered);
    report_json.push_back(c);
  }
  result.plots_rendered = all_rendered && !comparisons.empty();

  const nlohmann::json report = {{"schema", "whirl.report"},
                                 {"schema_version", 1},
                                 {"provenance", options.provenance},
                                 {"comparisons", report_json}};
  out.Add("report.json", JsonFileText(report));
  out.Add("index.html",
          IndexHtml(options, result.warnings, ControlLoads(comparisons, options), body.str(),
                    comparisons.empty() ? "" : comparisons.front().model_family));
  result.files = out.Commit();
  result.index_html = dir / "index.html";
  return result;
}

}  // namespace whirl::compare
