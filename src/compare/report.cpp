#include "compare/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "core/csv.h"
#include "core/json_file.h"
#include "core/numbers.h"
#include "core/output_dir.h"
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

// The gnuplot script for one screw: reads the CSVs and writes the PNGs beside it.
std::string GnuplotScript(const ScrewComparison& c, const std::string& slug, const PlotFiles& f,
                          const std::string& terminal) {
  const double t_end = c.truth.time_s.back();
  const double settle = std::max(c.predicted_curve.settle_time_s, c.experience_ramp_time_s);
  const double t_zoom = std::min(t_end, std::max(60.0, 3.0 * settle));
  const double l = c.screw.thread_length_mm;
  const std::string& name = c.screw.name;  // user-supplied: only ever inside GnuplotString
  std::ostringstream s;
  s << "# gnuplot script written by whirl; re-run with: gnuplot " << slug << ".gp\n"
    << "set datafile separator ','\nset datafile commentschars '#'\n"
    << "set terminal " << terminal << "\nset grid\nset key right bottom box opaque\n"
    << "set style line 1 lc rgb '#1f77b4' lw 2\nset style line 2 lc rgb '#d62728' lw 2 dt 2\n"
    << "set style line 3 lc rgb '#2ca02c' lw 2\nset style line 4 lc rgb '#ff7f0e' lw 2 dt 4\n"
    << "set style line 5 lc rgb '#000000' pt 7 ps 0.8\n";
  // Elongation: truth vs prediction, compensation points, traditional ramp.
  s << "set output " << GnuplotString(f.elongation) << "\n"
    << "set title "
    << GnuplotString(name + ": elongation of the unmachined section (first " +
                     FormatDecimals(t_zoom, 0) + " s of " + FormatDecimals(t_end, 0) +
                     " s cutting time)")
    << " noenhanced\n"
    << "set xlabel 'cutting time t [s]'\nset ylabel 'elongation [um]'\n"
    << "set xrange [0:" << t_zoom << "]\nset yrange [0:*]\n"
    << "plot " << GnuplotString(slug + "_elongation.csv")
    << " using 1:2 with lines ls 1 title 'simulated truth "
    << "(disturbed)', \\\n"
    << "  '' using 1:3 with lines ls 2 title 'predicted arctan curve (model)', \\\n"
    << "  '' using 1:5 with lines ls 3 title '840D compensation applied (model plan)', \\\n"
    << "  '' using 1:4 with lines ls 4 title 'traditional compensation (class-mean curve, 840D "
       "plan)', \\\n"
    << "  " << GnuplotString(slug + "_points.csv")
    << " using 1:3 with points ls 5 title 'compensation points "
    << "(SD43900/10/20 breakpoints)'\n"
    << "set output\n";
  // Lead deviation along the whole thread.
  s << "set key below horizontal box\nset bmargin 6\n"
    << "set output " << GnuplotString(f.lead) << "\n"
    << "set title "
    << GnuplotString(name +
                     ": travel deviation along the thread after cooling (actual - specified)")
    << " noenhanced\n"
    << "set xlabel 'position from the thread start [mm]'\nset ylabel 'travel deviation [um]'\n"
    << "set xrange [0:" << l << "]\nset yrange [*:*]\n"
    << "plot " << GnuplotString(slug + "_lead.csv")
    << " using 1:2 with lines ls 2 title 'no compensation', \\\n"
    << "  '' using 1:3 with lines ls 4 title 'traditional (class-mean curve)', \\\n"
    << "  '' using 1:4 with lines ls 3 title 'model-based (840D plan)'\n"
    << "set output\n";
  s << "set output " << GnuplotString(f.lead_start) << "\n"
    << "set title "
    << GnuplotString(name + ": travel deviation, first " + FormatDecimals(std::min(l, 1000.0), 0) +
                     " mm of the thread")
    << " noenhanced\n"
    << "set xrange [0:" << std::min(l, 1000.0) << "]\n"
    << "replot\nset output\n";
  return s.str();
}

std::string MetricsTable(const ScrewComparison& c) {
  const auto& n = c.Outcome(Strategy::kNone);
  const auto& t = c.Outcome(Strategy::kTraditional);
  const auto& m = c.Outcome(Strategy::kModel);
  std::ostringstream h;
  h << "<table><tr><th>metric [um]</th><th>no compensation</th><th>traditional</th>"
       "<th>model-based</th><th>model vs traditional</th><th>model vs none</th></tr>\n";
  auto row = [&](const std::string& name, double a, double b, double d,
                 const std::optional<double>& r1, const std::optional<double>& r2) {
    h << "<tr><td>" << name << "</td><td>" << FormatDecimals(a, 1) << "</td><td>"
      << FormatDecimals(b, 1) << "</td><td>" << FormatDecimals(d, 1) << "</td><td>" << Pct(r1)
      << "</td><td>" << Pct(r2) << "</td></tr>\n";
  };
  row("accumulated error within any 1000 mm", n.metrics.accumulated_1000_um,
      t.metrics.accumulated_1000_um, m.metrics.accumulated_1000_um,
      c.model_vs_traditional.accumulated_1000_pct, c.model_vs_none.accumulated_1000_pct);
  row("accumulated error over the whole thread", n.metrics.accumulated_total_um,
      t.metrics.accumulated_total_um, m.metrics.accumulated_total_um,
      c.model_vs_traditional.accumulated_total_pct, c.model_vs_none.accumulated_total_pct);
  row("e_a (mean travel deviation over l_u)", n.metrics.e_a_um, t.metrics.e_a_um, m.metrics.e_a_um,
      c.model_vs_traditional.e_a_pct, c.model_vs_none.e_a_pct);
  row("v_u (band over l_u)", n.metrics.v_u_um, t.metrics.v_u_um, m.metrics.v_u_um,
      c.model_vs_traditional.v_u_pct, c.model_vs_none.v_u_pct);
  row("v_300 (band within 300 mm)", n.metrics.v_300_um, t.metrics.v_300_um, m.metrics.v_300_um,
      c.model_vs_traditional.v_300_pct, c.model_vs_none.v_300_pct);
  if (n.metrics.v_2pi_um && t.metrics.v_2pi_um && m.metrics.v_2pi_um)
    row("v_2pi (band within one revolution)", *n.metrics.v_2pi_um, *t.metrics.v_2pi_um,
        *m.metrics.v_2pi_um, c.model_vs_traditional.v_2pi_pct, c.model_vs_none.v_2pi_pct);
  h << "<tr class='cls'><td>ISO 3408-3 class reached</td><td>" << ToString(n.iso.reached)
    << "</td><td>" << ToString(t.iso.reached) << "</td><td>" << ToString(m.iso.reached)
    << "</td><td colspan='2'></td></tr>\n</table>\n<ul class='small'>\n";
  for (const auto* o : {&n, &t, &m})
    h << "<li><b>" << ToString(o->strategy) << "</b>: " << HtmlEscape(o->iso.message) << "</li>\n";
  h << "</ul>\n";
  // Every baseline, absolute micrometres first (compare/traditional.h says why each is
  // a fair stand-in).
  h << "<table><tr><th>strategy</th><th>within 1000 mm [um]</th><th>whole thread [um]</th>"
       "<th>ISO class</th><th>model vs it, 1000 mm</th></tr>\n";
  for (const auto& o : c.outcomes) {
    const auto r = Reductions(m.metrics, o.metrics).accumulated_1000_pct;
    h << "<tr><td>" << ToString(o.strategy) << "</td><td>"
      << FormatDecimals(o.metrics.accumulated_1000_um, 2) << "</td><td>"
      << FormatDecimals(o.metrics.accumulated_total_um, 2) << "</td><td>" << ToString(o.iso.reached)
      << "</td><td>" << (o.strategy == Strategy::kModel ? "" : Pct(r)) << "</td></tr>\n";
  }
  h << "</table>\n<p class='small'>ramp: class plateau ramped in linearly (the previous rule); "
       "traditional: class mean plateau and settle time with the model's curve shape and plan; "
       "regression: log-linear least squares of both features on the five inputs, same history, "
       "curve and plan; model: the workpiece model, "
    << HtmlEscape(c.model_description) << ".</p>\n";
  return h.str();
}

// The screw's data files: the elongation with the compensations applied, the plan's compensation
// points and the travel deviation of each strategy (CSV with `options.provenance` as comments).
void AddScrewData(const ScrewComparison& c, const std::string& slug, const ReportOptions& options,
                  OutputDir& out) {
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < c.truth.size(); ++i) {
    const double t = c.truth.time_s[i];
    rows.push_back({t, c.truth.elongation_um[i], c.predicted_curve.ElongationUm(t),
                    c.compensation_um[static_cast<std::size_t>(Strategy::kTraditional)][i],
                    c.compensation_um[static_cast<std::size_t>(Strategy::kModel)][i]});
  }
  out.Add(slug + "_elongation.csv",
          FormatCsv({"time_s", "truth_elongation_um", "predicted_elongation_um",
                     "traditional_compensation_um", "model_compensation_um"},
                    rows,
                    Comments(options, "elongation of the unmachined section of screw '" +
                                          c.screw.name + "' and the compensation applied")));
  out.Add(slug + "_points.csv",
          interp::FormatPointsCsv(
              c.plan, Comments(options,
                               "compensation points of the 840D plan (the last row is the "
                               "thread end, where the values found before the cut are "
                               "restored)")));
  rows.clear();
  const auto& ln = c.Outcome(Strategy::kNone).lead;
  const auto& lt = c.Outcome(Strategy::kTraditional).lead;
  const auto& lm = c.Outcome(Strategy::kModel).lead;
  for (std::size_t i = 0; i < ln.size(); ++i)
    rows.push_back({ln.position_mm[i], ln.deviation_um[i], lt.deviation_um[i], lm.deviation_um[i]});
  out.Add(slug + "_lead.csv", FormatCsv({"position_mm", "none_deviation_um",
                                         "traditional_deviation_um", "model_deviation_um"},
                                        rows,
                                        Comments(options,
                                                 "travel deviation (actual - specified travel from "
                                                 "the thread start) of screw '" +
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
  const std::filesystem::path stage = std::filesystem::absolute(out.Staging());
  const int rc = RunProgram({options.gnuplot_command, slug + ".gp"}, stage, stage / log);
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

// The features of the truth, the model's prediction and the traditional rule's class.
std::string FeaturesTable(const ScrewComparison& c) {
  std::ostringstream body;
  body << "<table><tr><th></th><th>max elongation [um]</th><th>settle time [s]</th></tr>\n"
       << "<tr><td>simulated truth (seed " << c.seed << ", disturbances "
       << (c.disturbances_on ? "on" : "off") << ")</td><td>"
       << FormatDecimals(c.truth_features.max_elongation_um, 1) << "</td><td>"
       << FormatDecimals(c.truth_features.settle_time_s, 0) << "</td></tr>\n"
       << "<tr><td>model prediction (+- 1 std)</td><td>"
       << FormatDecimals(c.prediction.mean.max_elongation_um, 1) << " +- "
       << FormatDecimals(c.prediction.stddev.max_elongation_um, 1) << "</td><td>"
       << FormatDecimals(c.prediction.mean.settle_time_s, 0) << " +- "
       << FormatDecimals(c.prediction.stddev.settle_time_s, 0) << "</td></tr>\n"
       << "<tr><td>traditional rule (class "
       << FormatDecimals(c.experience_class.nominal_diameter_mm, 0) << " mm, "
       << c.experience_class.screws << " past screws)</td><td>"
       << FormatDecimals(c.experience_class.plateau_um, 1) << "</td><td>"
       << FormatDecimals(c.experience_ramp_time_s, 0) << " (ramp)</td></tr></table>\n";
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

// The screw's HTML section: inputs, features, plan, metrics, plots (or why not) and data links.
std::string ScrewSection(const ScrewComparison& c, const std::string& slug, const PlotFiles& files,
                         const std::set<std::string>& rendered) {
  std::ostringstream body;
  body << InputsSection(c) << FeaturesTable(c) << PlanParagraph(c) << MetricsTable(c);
  for (const std::string& png : {files.elongation, files.lead, files.lead_start}) {
    if (rendered.count(png) > 0)
      body << "<p><img src='" << png << "' alt='" << png << "'></p>\n";
    else
      body << "<p class='warn'>Plot " << png << " not rendered (see warnings).</p>\n";
  }
  body << "<p class='small'>Data: <a href='" << slug << "_elongation.csv'>" << slug
       << "_elongation.csv</a>, <a href='" << slug << "_points.csv'>" << slug
       << "_points.csv</a>, <a href='" << slug << "_lead.csv'>" << slug
       << "_lead.csv</a>, gnuplot script <a href='" << slug << ".gp'>" << slug << ".gp</a>.</p>\n";
  return body.str();
}

// The page: title, provenance, notes, warnings, how to read it, then the screws' sections.
std::string IndexHtml(const ReportOptions& options, const std::vector<std::string>& warnings,
                      const std::string& sections) {
  std::ostringstream html;
  html
      << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>"
      << HtmlEscape(options.title)
      << "</title>\n<style>body{font-family:sans-serif;max-width:1060px;margin:2em auto;color:#222}"
         "table{border-collapse:collapse;margin:0.6em 0}td,th{border:1px solid #bbb;padding:3px "
         "8px;"
         "text-align:right}td:first-child,th:first-child{text-align:left}th{background:#eee}"
         "tr.cls td{font-weight:bold}.small{font-size:0.85em;color:#555}.warn{color:#a00}"
         "img{max-width:100%;border:1px solid #ddd}</style></head><body>\n<h1>"
      << HtmlEscape(options.title) << "</h1>\n";
  for (const auto& p : options.provenance) html << "<p class='small'>" << HtmlEscape(p) << "</p>\n";
  for (const auto& n : options.notes) html << "<p>" << HtmlEscape(n) << "</p>\n";
  for (const auto& w : warnings) html << "<p class='warn'>warning: " << HtmlEscape(w) << "</p>\n";
  html << "<p>How to read this page. Each screw is cut in the simulator (the ground truth, with "
          "seeded disturbances the model never saw) three times: without compensation, with the "
          "traditional experience rule (one correction per diameter class, ramped in linearly over "
          "the machine's mean settle time, from the same past screws the model was trained on), "
          "and with the model-based 840D plan (prediction, arctangent curve, "
          "SD43900/SD43910/SD43920 "
          "segments). Travel deviation = actual minus specified travel from the thread start after "
          "cooling; accumulated error within 1000 mm = the largest max - min of the deviation "
          "within any 1000 mm of thread (the paper's figure), over the whole thread = max - min "
          "over the thread. e_a, v_u, v_300, v_2pi as ISO 3408-3 (about the least-squares mean "
          "travel line). Reductions are 100 (1 - model / baseline).</p>\n"
          "<p class='small'>ISO 3408-3 caveat: only some tolerance cells are confirmed by a source "
          "(Steinmeyer, HIWIN catalogue); the others are recalled values "
          "(datasets/standards/iso3408_3_lead_tolerances.csv). Treat the class as indicative.</p>\n"
       << sections << "</body></html>\n";
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
  out.Add("index.html", IndexHtml(options, result.warnings, body.str()));
  result.files = out.Commit();
  result.index_html = dir / "index.html";
  return result;
}

}  // namespace whirl::compare
