#include "compare/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/csv.h"
#include "core/json_file.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/safe_text.h"

#include "core/report_render.h"
#include "plan/load.h"

namespace whirl::compare {
namespace {

std::string Pct(const std::optional<double>& v) { return v ? FormatDecimals(*v, 1) + " %" : "-"; }

std::vector<std::string> Comments(const ReportOptions& o, const std::string& what) {
  std::vector<std::string> c{" " + what};
  for (const auto& p : o.provenance) c.push_back(" " + p);
  return c;
}


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

using report::Cell;
using report::Col;
using report::Series;
using report::SeriesKind;
using report::Text;

// The baselines whose compensation is drawn with a band of its own in the elongation plot (all
// compensating strategies but the model, whose band is the prediction's): the band columns of
// <slug>_elongation.csv, in this order.
std::vector<Strategy> BandedBaselines() {
  std::vector<Strategy> out;
  for (Strategy s : CompensatingStrategies())
    if (s != Strategy::kModel) out.push_back(s);
  return out;
}

std::size_t At(Strategy s) { return static_cast<std::size_t>(s); }

// Columns of <slug>_elongation.csv (gnuplot's numbers): time, truth, prediction, its band (4, 5),
// each compensating strategy's compensation from 6 on, then each banded baseline's -1 sd and
// +1 sd columns.
int CompensationColumn(Strategy s) {
  const auto all = CompensatingStrategies();
  return 6 + static_cast<int>(std::find(all.begin(), all.end(), s) - all.begin());
}
int BandLowColumn(Strategy s) {
  const auto banded = BandedBaselines();
  return 6 + static_cast<int>(CompensatingStrategies().size()) +
         2 * static_cast<int>(std::find(banded.begin(), banded.end(), s) - banded.begin());
}

// The screw's data files: <slug>_elongation.csv (the columns above), the plan's compensation
// points and the travel deviation of each strategy (CSV with `options.provenance` as comments).
// A baseline's elongation band is its compensation times 1 -+ its relative error
// (ScrewComparison::band_relative): the rule's plateau off by its typical error, scaled along
// the curve.
void AddScrewData(const ScrewComparison& c, const std::string& slug, const ReportOptions& options,
                  OutputDir& out) {
  const fit::ArctanCurve& low = c.band_curves[0];
  const fit::ArctanCurve& high = c.band_curves[1];
  std::vector<std::string> header{"time_s", "truth_elongation_um", "predicted_elongation_um",
                                  "predicted_minus_1sd_um", "predicted_plus_1sd_um"};
  for (Strategy st : CompensatingStrategies()) header.push_back(ToString(st) + "_compensation_um");
  for (Strategy st : BandedBaselines()) {
    header.push_back(ToString(st) + "_minus_1sd_um");
    header.push_back(ToString(st) + "_plus_1sd_um");
  }
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < c.truth.size(); ++i) {
    const double t = c.truth.time_s[i];
    rows.push_back({t, c.truth.elongation_um[i], c.predicted_curve.ElongationUm(t),
                    low.ElongationUm(t), high.ElongationUm(t)});
    for (Strategy st : CompensatingStrategies())
      rows.back().push_back(c.compensation_um[At(st)][i]);
    for (Strategy st : BandedBaselines()) {
      const double comp = c.compensation_um[At(st)][i], rel = c.band_relative[At(st)];
      rows.back().push_back(comp * (1 - rel));
      rows.back().push_back(comp * (1 + rel));
    }
  }
  out.Add(slug + "_elongation.csv",
          FormatCsv(header, rows,
                    Comments(options,
                             "elongation of the unmachined section of screw '" + c.screw.name +
                                 "', the prediction +- 1 sd (curves of the features at +-1 sd), "
                                 "the compensation applied, and each baseline's compensation "
                                 "times 1 -+ its leave-one-out relative error on the past "
                                 "screws")));
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

// <slug>_lead_band.csv: the model's travel deviation with plans of the prediction's -1 sd and
// +1 sd curves (ScrewComparison::band_leads); false when either has no plan.
bool AddBandData(const ScrewComparison& c, const std::string& slug, const ReportOptions& options,
                 OutputDir& out) {
  const lead::LeadDeviation& low = c.band_leads[0];
  const lead::LeadDeviation& high = c.band_leads[1];
  if (low.size() == 0 || low.size() != high.size()) return false;
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < low.size(); ++i)
    rows.push_back({low.position_mm[i], low.deviation_um[i], high.deviation_um[i]});
  out.Add(slug + "_lead_band.csv",
          FormatCsv({"position_mm", "model_minus_1sd_deviation_um", "model_plus_1sd_deviation_um"},
                    rows,
                    Comments(options, "travel deviation of screw '" + c.screw.name +
                                          "' had the model's plan been made from the prediction's "
                                          "-1 sd and +1 sd curves (the band around 'model')")));
  return true;
}

// The two panels of the workpiece plots: the model with the baselines a headline compares it
// against (ramp, traditional, regression), then the three history rules traditional is chosen
// from. Fewer bands per panel keep the lines readable.
const std::vector<Strategy>& HeadlineBaselines() {
  static const std::vector<Strategy> s{Strategy::kRamp, Strategy::kTraditional,
                                       Strategy::kRegression};
  return s;
}
const std::vector<Strategy>& HistoryRuleStrategies() {
  static const std::vector<Strategy> s{Strategy::kClass, Strategy::kTable, Strategy::kNearest};
  return s;
}

// A band's legend words: the strategy, its sd at the plateau.
std::string BandTitle(Strategy s, const ScrewComparison& c) {
  return ToString(s) + " +- 1 sd (" + FormatDecimals(c.band_sd_um[At(s)], 1) +
         " um at the plateau)";
}

// Elongation: the truth, then per panel the baselines' compensation with their bands (columns of
// <slug>_elongation.csv: see BandLowColumn); the first panel also the prediction with its band,
// the model's compensation and the plan's points.
report::Figure ElongationFigure(const ScrewComparison& c, const std::string& slug) {
  const double t_end = c.truth.time_s.back();
  const double settle = std::max(c.predicted_curve.settle_time_s, c.experience_ramp_time_s);
  const double t_zoom = std::min(t_end, std::max(60.0, 3.0 * settle));
  const std::string csv = slug + "_elongation.csv";
  const auto panel = [&](const std::string& title, const std::vector<Strategy>& baselines) {
    report::Panel p;
    p.title = title;
    p.ylabel = "elongation [um]";
    p.x = {0, t_zoom};
    p.y = {0, NAN};
    for (Strategy st : baselines)
      if (c.band_sd_um[At(st)] > 0)
        p.series.push_back({csv, -1, {Col(1), Col(BandLowColumn(st)), Col(BandLowColumn(st) + 1)},
                            SeriesKind::kBand, ToString(st), "", 1.5, false, BandTitle(st, c)});
    p.series.push_back({csv, -1, {Col(1), Col(2)}, SeriesKind::kLine, "measured", "", 1.5, false,
                        "simulated truth (disturbed)"});
    for (Strategy st : baselines)
      p.series.push_back({csv, -1, {Col(1), Col(CompensationColumn(st))}, SeriesKind::kLine,
                          ToString(st), "", 1.5, false,
                          "compensation: " + StrategyLabel(st, c.model_family)});
    return p;
  };
  report::Panel a = panel(c.screw.name + ": elongation of the unmachined section (first " +
                              FormatDecimals(t_zoom, 0) + " s of " + FormatDecimals(t_end, 0) +
                              " s cutting time): the model and the headline baselines",
                          HeadlineBaselines());
  a.series.insert(a.series.begin(),
                  {csv, -1, {Col(1), Col(4), Col(5)}, SeriesKind::kBand, "prediction", "", 1.5,
                   false, "prediction +- 1 sd (curves of the features at -+1 sd)"});
  a.series.push_back({csv, -1, {Col(1), Col(3)}, SeriesKind::kLine, "prediction", "", 1.5, false,
                      "predicted arctan curve (model)"});
  a.series.push_back({csv, -1, {Col(1), Col(CompensationColumn(Strategy::kModel))},
                      SeriesKind::kLine, ToString(Strategy::kModel), "", 1.5, false,
                      "compensation: " + StrategyLabel(Strategy::kModel, c.model_family)});
  a.series.push_back({slug + "_points.csv", -1, {Col(1), Col(3)}, SeriesKind::kPoints, "",
                      "#000000", 1.5, false, "SD43900/10/20 breakpoints (model plan)"});
  report::Panel b = panel("the history rules traditional is chosen from", HistoryRuleStrategies());
  b.xlabel = "cutting time t [s]";
  report::Figure f;
  f.stem = slug + "_elongation";
  f.alt = "elongation of " + c.screw.name;
  f.height_px = 900;
  f.panels = {a, b};
  return f;
}

// Travel deviation along the thread (x from 0 to `x_end_mm`) in the two panels: none, the
// model (with its +-1 sd band when `band`: plans of the prediction's band curves) and the
// headline baselines; none, the model and the history rules. Each baseline with its +-1 sd
// band (core/report_document.h SdBand: the curve -+ ScrewComparison::band_sd_um).
report::Figure LeadFigure(const ScrewComparison& c, const std::string& slug,
                          const std::string& stem, double x_end_mm, const std::string& title,
                          bool band) {
  const std::string csv = slug + "_lead.csv";
  const auto column = [&c](Strategy s) {
    for (std::size_t k = 0; k < c.outcomes.size(); ++k)
      if (c.outcomes[k].strategy == s) return static_cast<int>(k) + 2;
    return 0;
  };
  const auto panel = [&](const std::string& what, const std::vector<Strategy>& baselines) {
    report::Panel p;
    p.title = what;
    p.ylabel = "travel deviation [um]";
    p.x = {0, x_end_mm};
    if (band)
      p.series.push_back({slug + "_lead_band.csv", -1, {Col(1), Col(2), Col(3)},
                          SeriesKind::kBand, ToString(Strategy::kModel), "", 1.5, false,
                          "model +- 1 sd (plans of the prediction's -1 sd and +1 sd curves)"});
    for (Strategy st : baselines)
      if (c.band_sd_um[At(st)] > 0)
        p.series.push_back(report::SdBand(csv, Col(1), column(st), c.band_sd_um[At(st)],
                                          ToString(st), BandTitle(st, c)));
    std::vector<Strategy> lines{Strategy::kNone, Strategy::kModel};
    lines.insert(lines.end(), baselines.begin(), baselines.end());
    for (Strategy st : lines)
      p.series.push_back({csv, -1, {Col(1), Col(column(st))}, SeriesKind::kLine, ToString(st),
                          "", 1.5, false, StrategyLabel(st, c.model_family)});
    return p;
  };
  report::Panel a = panel(c.screw.name + ": " + title + ": the model and the headline baselines",
                          HeadlineBaselines());
  report::Panel b = panel("the history rules traditional is chosen from", HistoryRuleStrategies());
  b.xlabel = "position from the thread start [mm]";
  report::Figure f;
  f.stem = stem;
  f.alt = c.screw.name + ": " + title;
  f.height_px = 860;
  f.panels = {a, b};
  return f;
}

// One row per strategy: the accumulated errors, the ISO 3408-3 figures and class, and how much
// less the model leaves than the strategy.
report::Table MetricsTable(const ScrewComparison& c) {
  const auto& m = c.Outcome(Strategy::kModel);
  bool v_2pi = true;
  for (const auto& o : c.outcomes) v_2pi = v_2pi && o.metrics.v_2pi_um.has_value();
  report::Table t;
  t.series_rows = true;
  t.header = {"strategy", "within any 1000 mm [um]", "whole thread [um]", "e_a [um]", "v_u [um]",
              "v_300 [um]"};
  if (v_2pi) t.header.push_back("v_2pi [um]");
  for (const char* h : {"ISO 3408-3 class", "model vs it, 1000 mm", "model vs it, thread"})
    t.header.push_back(h);
  for (const auto& o : c.outcomes) {
    const MetricReductions r = Reductions(m.metrics, o.metrics);
    const bool model = o.strategy == Strategy::kModel;
    if (model) t.highlight.push_back(t.rows.size());
    std::vector<Cell> row{ToString(o.strategy), FormatDecimals(o.metrics.accumulated_1000_um, 1),
                          FormatDecimals(o.metrics.accumulated_total_um, 1),
                          FormatDecimals(o.metrics.e_a_um, 1), FormatDecimals(o.metrics.v_u_um, 1),
                          FormatDecimals(o.metrics.v_300_um, 1)};
    if (v_2pi) row.push_back(FormatDecimals(*o.metrics.v_2pi_um, 1));
    row.push_back(ToString(o.iso.reached));
    row.push_back(model ? "" : Pct(r.accumulated_1000_pct));
    row.push_back(model ? "" : Pct(r.accumulated_total_pct));
    t.rows.push_back(std::move(row));
  }
  return t;
}

std::vector<report::Block> MetricsNotes(const ScrewComparison& c) {
  report::List iso;
  iso.tone = report::Tone::kSmall;
  for (const auto& o : c.outcomes)
    iso.items.push_back({report::Bold(ToString(o.strategy)), Text(": " + o.iso.message)});
  const report::Paragraph words{
      {Text("none: no compensation; ramp: the class plateau ramped in linearly over the mean "
            "settle time (the previous rule); traditional: the strongest of the history rules "
            "class, table and nearest (chosen by leave-one-out on the history, here " +
            ToString(c.traditional_rule) +
            "); class: diameter-class means; table: the experience table; nearest: the 3 nearest "
            "past screws; regression: log-linear least squares of both features on the five "
            "inputs. All but none and ramp use the model's curve shape and the same 840D "
            "planning; model: the workpiece model, " +
            c.model_description + ". \"model vs it\" = 100 (1 - model / it).")},
      report::Tone::kSmall};
  return {report::MakeBlock(iso), report::MakeBlock(words)};
}

// The screw's heading, its inputs and, when the model extrapolates, the inputs outside its domain.
void AddInputs(const ScrewComparison& c, report::Document* doc) {
  const auto in = c.screw.process;
  doc->Add(report::Heading{2, c.screw.name, ""});
  doc->Say("Inputs: hardness " + FormatDecimals(in.hardness_hrc, 1) + " HRC, diameter " +
           FormatDecimals(in.diameter_mm, 1) + " mm, lead " + FormatDecimals(in.pitch_mm, 2) +
           " mm, raceway radius " + FormatDecimals(in.raceway_radius_mm, 2) +
           " mm, cutting speed " + FormatDecimals(in.cutting_speed_m_min, 0) + " m/min; blank " +
           FormatDecimals(c.screw.length_mm, 0) + " mm, thread " +
           FormatDecimals(c.screw.thread_length_mm, 0) + " mm; axial feed " +
           FormatDecimals(c.kinematics.axial_feed_mm_min, 1) + " mm/min, cutting time " +
           FormatDecimals(c.kinematics.cutting_time_s / 60, 1) + " min.");
  if (c.prediction.outside_domain) {
    std::string fields;
    for (const auto& f : c.prediction.outside_domain_fields)
      fields += (fields.empty() ? "" : ", ") + f;
    doc->Say("The model extrapolates: outside its training domain in " + fields + ".",
             report::Tone::kWarn);
  }
}

// A strategy's +-1 sd band in words for the features table: "1.9 (11.8 % leave-one-out)".
std::string BandCell(const ScrewComparison& c, Strategy s, const std::string& source) {
  if (!(c.band_sd_um[At(s)] > 0)) return "- (no band: " + source + " unknown)";
  return FormatDecimals(c.band_sd_um[At(s)], 1) + " (" +
         FormatDecimals(100 * c.band_relative[At(s)], 1) + " % " + source + ")";
}

// The features each strategy works from: the truth's, the model's (+- 1 sd), the ramp's class
// plateau and ramp time, the traditional rule's class means and the regression's, each with the
// +-1 sd of its plateau that its bands show (ScrewComparison::band_sd_um).
report::Table FeaturesTable(const ScrewComparison& c) {
  const std::string loo = "leave-one-out";
  report::Table t;
  t.header = {"", "max elongation [um]", "settle time [s]", "band +-1 sd at the plateau [um]"};
  auto row = [&t](const std::string& what, const std::string& l, const std::string& s,
                  const std::string& band) { t.rows.push_back({what, l, s, band}); };
  row("simulated truth (seed " + std::to_string(c.seed) + ", disturbances " +
          (c.disturbances_on ? "on" : "off") + ")",
      FormatDecimals(c.truth_features.max_elongation_um, 1),
      FormatDecimals(c.truth_features.settle_time_s, 0), "");
  row("model prediction (+- 1 sd)",
      FormatDecimals(c.prediction.mean.max_elongation_um, 1) + " +- " +
          FormatDecimals(c.prediction.stddev.max_elongation_um, 1),
      FormatDecimals(c.prediction.mean.settle_time_s, 0) + " +- " +
          FormatDecimals(c.prediction.stddev.settle_time_s, 0),
      BandCell(c, Strategy::kModel, "predictive sd"));
  const std::string cls = "class " + FormatDecimals(c.experience_class.nominal_diameter_mm, 0) +
                          " mm, " + std::to_string(c.experience_class.screws) + " past screws";
  row("ramp (" + cls + ")", FormatDecimals(c.experience_class.plateau_um, 1),
      FormatDecimals(c.experience_ramp_time_s, 0) + " (linear ramp)",
      BandCell(c, Strategy::kRamp, loo));
  row("traditional (= " + ToString(c.traditional_rule) + ", chosen on the history)",
      FormatDecimals(c.traditional_features.max_elongation_um, 1),
      FormatDecimals(c.traditional_features.settle_time_s, 0),
      BandCell(c, Strategy::kTraditional, loo));
  for (std::size_t k = 0; k < kHistoryRuleCount; ++k) {  // HistoryRule order, as the panel's
    const Strategy st = HistoryRuleStrategies()[k];
    row(ToString(st) + (k == 0 ? " (" + cls + ", means)" : std::string(" (history rule)")),
        FormatDecimals(c.history_features[k].max_elongation_um, 1),
        FormatDecimals(c.history_features[k].settle_time_s, 0), BandCell(c, st, loo));
  }
  if (c.regression_features.max_elongation_um > 0)
    row("regression (log-linear on the five inputs)",
        FormatDecimals(c.regression_features.max_elongation_um, 1),
        FormatDecimals(c.regression_features.settle_time_s, 0),
        BandCell(c, Strategy::kRegression, loo));
  else
    row("regression", "-", "- (the history has no regression: equals none)", "");
  return t;
}

// The disturbances of the truth and the 840D plan's figures.
std::string PlanText(const ScrewComparison& c) {
  return "Disturbances of the truth (unknown to the model): heat partition x" +
         FormatDecimals(c.disturbances.heat_partition_factor, 3) + ", expansion coefficient x" +
         FormatDecimals(c.disturbances.expansion_factor, 3) + ", ambient drift " +
         FormatDecimals(c.disturbances.ambient_drift_k_per_h, 3) + " K/h. 840D plan: " +
         std::to_string(c.plan.segments.size()) + " segments (" +
         std::to_string(c.plan.point_count) + " points; uniform spacing would need " +
         (c.plan.uniform_point_count > 0 ? std::to_string(c.plan.uniform_point_count)
                                         : std::string("more than 1000000")) +
         "), max |chord - curve| " + FormatDecimals(c.plan.max_deviation_um, 2) +
         " um, max |SD43910| " + FormatFixed(c.plan.max_abs_slope, interp::kDecimalsSd43910) +
         " (MD32760 cap " + FormatFixed(c.plan.options.md32760, 4) + "), axis " +
         c.plan.options.axis + ", sign " + interp::ToString(c.plan.options.sign) + ".";
}

// The screw's part of the page: inputs, the strategies' results, plots, the features, the plan
// and the data links.
void AddScrew(const ScrewComparison& c, const std::string& slug, bool band,
              report::Document* doc) {
  AddInputs(c, doc);
  doc->Add(MetricsTable(c)).Add(MetricsNotes(c));
  const double l = c.screw.thread_length_mm;
  doc->Add(ElongationFigure(c, slug));
  doc->Add(LeadFigure(c, slug, slug + "_lead", l,
                      "travel deviation along the thread after cooling (actual - specified)",
                      band));
  doc->Add(LeadFigure(c, slug, slug + "_lead_start", std::min(l, 1000.0),
                      "travel deviation, first " + FormatDecimals(std::min(l, 1000.0), 0) +
                          " mm of the thread",
                      band));
  doc->Say("Features each strategy works from:").Add(FeaturesTable(c));
  doc->Say(PlanText(c), report::Tone::kSmall);
  report::Paragraph data{{Text("Data: ")}, report::Tone::kSmall};
  std::vector<std::string> files{slug + "_elongation.csv", slug + "_points.csv",
                                 slug + "_lead.csv"};
  if (band) files.push_back(slug + "_lead_band.csv");
  for (const std::string& f : files) {
    data.spans.push_back(report::Link(f, f));
    data.spans.push_back(Text(", "));
  }
  data.spans.push_back(Text("gnuplot scripts beside each picture (<name>.gp)."));
  doc->Add(data);
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
void AddHowToRead(const std::string& history, const std::string& model_family,
                  report::Document* doc) {
  std::string names;
  for (Strategy s : kStrategies)
    names += (names.empty() ? "" : "; ") + StrategyLabel(s, model_family);
  doc->Add(report::Heading{2, "How to read this page", ""});
  doc->Say("Each screw is cut in the simulator (the ground truth, with seeded disturbances the "
           "model never saw) once per strategy: " +
           names +
           ". The curve-based strategies share the model's curve shape and 840D planning; the "
           "history rules (ramp, class, table, nearest, traditional, regression) use the past "
           "screws of " +
           (history.empty() ? "the history named under the title" : history) +
           ". Travel deviation = actual minus specified travel from the thread start after "
           "cooling; accumulated error within 1000 mm = the largest max - min of the deviation "
           "within any 1000 mm of thread (the paper's figure), over the whole thread = max - min "
           "over the thread. e_a, v_u, v_300, v_2pi as ISO 3408-3 (about the least-squares mean "
           "travel line).");
  doc->Add(report::Heading{3, "The shaded +-1 sd bands", ""});
  doc->Say(
      "Every plotted prediction has a band computed from training data only (the past screws "
      "and the model's training), never from the screw being cut. model: in the elongation plot "
      "the arctangent curves of the predicted features at -+1 sd (the network's predictive sd); "
      "in the travel-deviation plots the model's deviation had the plan been made from either "
      "curve. ramp, traditional, regression, class, table, nearest: the rule's leave-one-out "
      "mean relative error on the past screws (each past screw predicted by the rule built "
      "without it, the error of plateau and settle time averaged: the score traditional is "
      "chosen by; the regression refitted without each screw; traditional takes its rule's) "
      "times the rule's plateau for this screw (the table of features gives both). In the "
      "elongation plot the band is the compensation times 1 -+ that error, in the "
      "travel-deviation plots the curve -+ that many um. It is the scale of how far the "
      "compensation may be off, not an interval computed for this lead curve; none compensates "
      "nothing and has no band. The same definitions as the machine report's bands.");
  doc->Say("ISO 3408-3 caveat: only some tolerance cells are confirmed by a source (Steinmeyer, "
           "HIWIN catalogue); the others are recalled values "
           "(datasets/standards/iso3408_3_lead_tolerances.csv). Treat the class as indicative.",
           report::Tone::kSmall);
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
  report::Document doc;
  doc.title = options.title;
  doc.provenance = options.provenance;
  doc.Add(plan::LoadBox(ControlLoads(comparisons, options)));
  for (const auto& n : options.notes) doc.Say(n);
  std::vector<std::string> slugs;
  nlohmann::json report_json = nlohmann::json::array();
  for (const ScrewComparison& c : comparisons) {
    std::string slug = Slug(c.screw.name);
    while (std::find(slugs.begin(), slugs.end(), slug) != slugs.end()) slug += "_";
    slugs.push_back(slug);
    AddScrewData(c, slug, options, out);
    const bool band = AddBandData(c, slug, options, out);
    AddScrew(c, slug, band, &doc);
    report_json.push_back(c);
  }
  AddHowToRead(options.history, comparisons.empty() ? "" : comparisons.front().model_family,
               &doc);
  const nlohmann::json report = {{"schema", "whirl.report"},
                                 {"schema_version", 1},
                                 {"provenance", options.provenance},
                                 {"comparisons", report_json}};
  out.Add("report.json", JsonFileText(report));
  report::RenderOptions ro;
  ro.plots = options.plots;
  ro.gnuplot = options.gnuplot_command;
  const report::RenderResult rendered = report::RenderReport(doc, out, ro);
  ReportResult result;
  result.warnings = rendered.warnings;
  result.plots_rendered = rendered.plots_rendered && !comparisons.empty();
  result.files = out.Commit();
  result.index_html = dir / "index.html";
  return result;
}

}  // namespace whirl::compare
