// Output documents of the monitor: timeline and events CSV, JSON, text table, HTML page.
#include "drift/monitor_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <sstream>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "core/plot_style.h"
#include "core/report_render.h"
#include "core/safe_text.h"
#include "drift/documents.h"
#include "drift/load_box.h"

namespace whirl::drift {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> WithComments(const std::vector<std::string>& c, const std::string& what) {
  std::vector<std::string> out{what};
  out.insert(out.end(), c.begin(), c.end());
  return out;
}

nlohmann::json EventJson(const MonitorEvent& e) {
  nlohmann::json j = {
      {"kind", ToString(e.kind)}, {"sample", e.sample}, {"time", e.time}, {"message", e.message}};
  if (e.kind == MonitorEvent::Kind::kCheck || e.kind == MonitorEvent::Kind::kRefitMeasurement) {
    j["measured_um"] = e.measured_um;
    j["predicted_um"] = e.predicted_um;
  }
  if (e.kind == MonitorEvent::Kind::kCheck) {
    j["threshold_um"] = e.threshold_um;
    j["valid"] = e.valid;
  }
  if (e.kind == MonitorEvent::Kind::kUpdate)
    j["coefficients"] =
        std::vector<double>(e.coefficients.data(), e.coefficients.data() + e.coefficients.size());
  return j;
}

}  // namespace

std::string MonitorTimelineHeader(bool time_from_index, const std::vector<UpdateRule>& rules,
                                  const std::vector<std::string>& comments, bool day_column) {
  std::vector<std::string> header;
  if (day_column) header.push_back("day");
  header.push_back(time_from_index ? "sample" : "time_min");
  header.push_back("measured_um");
  for (UpdateRule u : rules) header.push_back(ToString(u) + "_um");
  for (UpdateRule u : rules) header.push_back(ToString(u) + "_residual_um");
  return FormatCsv(header, {}, comments);
}

void AppendTimelineRow(double time, double measured, const std::vector<double>& predicted,
                       std::string* out, int day) {
  const auto cell = [&](double v) {
    if (!out->empty() && out->back() != '\n') out->push_back(',');
    out->append(FormatNumber(v));
  };
  if (day > 0) cell(day);
  cell(time);
  cell(measured);
  for (double p : predicted) cell(p);
  for (double p : predicted) cell(measured - p);
  out->push_back('\n');
}

std::string MonitorTimelineCsv(const MonitorResult& r, const std::vector<std::string>& comments) {
  std::vector<UpdateRule> rules;
  for (const auto& s : r.strategies) rules.push_back(s.rule);
  std::string out =
      MonitorTimelineHeader(r.time_from_index, rules, WithComments(comments, "monitor timeline of " + r.run));
  std::vector<double> predicted(r.strategies.size());
  for (Eigen::Index k = 0; k < r.measured_um.size(); ++k) {
    for (std::size_t i = 0; i < predicted.size(); ++i) predicted[i] = r.strategies[i].predicted_um(k);
    AppendTimelineRow(r.time[static_cast<std::size_t>(k)], r.measured_um(k), predicted, &out);
  }
  return out;
}

MonitorResult PlotRows(const MonitorResult& r, int columns) {
  std::vector<std::vector<double>> series{
      std::vector<double>(r.measured_um.data(), r.measured_um.data() + r.measured_um.size())};
  for (const auto& st : r.strategies) {
    series.emplace_back(st.predicted_um.data(), st.predicted_um.data() + st.predicted_um.size());
    series.emplace_back(r.measured_um.size());
    for (Eigen::Index k = 0; k < r.measured_um.size(); ++k)
      series.back()[static_cast<std::size_t>(k)] = r.measured_um(k) - st.predicted_um(k);
  }
  const std::vector<std::size_t> keep = M4Rows(r.time, series, columns);
  MonitorResult out = r;
  const auto pick = [&](const Eigen::VectorXd& v) {
    Eigen::VectorXd p(static_cast<Eigen::Index>(keep.size()));
    for (std::size_t i = 0; i < keep.size(); ++i)
      p(static_cast<Eigen::Index>(i)) = v(static_cast<Eigen::Index>(keep[i]));
    return p;
  };
  out.time.clear();
  out.rows_kept.clear();
  for (std::size_t i : keep) {
    out.time.push_back(r.time[i]);
    out.rows_kept.push_back(static_cast<long long>(r.rows_kept.empty() ? i : r.rows_kept[i]));
  }
  out.measured_um = pick(r.measured_um);
  if (r.measurement_noise_um.size() == r.measured_um.size())
    out.measurement_noise_um = pick(r.measurement_noise_um);
  for (auto& st : out.strategies) st.predicted_um = pick(st.predicted_um);
  for (auto& b : out.baselines)
    if (b.predicted_um.size() == r.measured_um.size()) b.predicted_um = pick(b.predicted_um);
  return out;
}

namespace {

// The events table's column names; without recorded time the time axis is the sample index: one
// column, not two.
std::string EventsHeader(const MonitorResult& r) {
  return std::string("rule,kind,sample,") + (r.time_from_index ? "" : "time_min,") +
         "measured_um,predicted_um,threshold_um,valid,message\n";
}

// The events table's rows, each after `prefix` (the week's day cell). Built row by row rather
// than by splitting a finished table at line ends, which would cut a quoted message in two.
void EventRows(const MonitorResult& r, const std::string& prefix, std::ostream& o) {
  for (const auto& s : r.strategies)
    for (const auto& e : s.events) {
      const bool measured =
          e.kind == MonitorEvent::Kind::kCheck || e.kind == MonitorEvent::Kind::kRefitMeasurement;
      const bool check = e.kind == MonitorEvent::Kind::kCheck;
      o << prefix << ToString(s.rule) << "," << ToString(e.kind) << "," << e.sample << ","
        << (r.time_from_index ? "" : FormatNumber(e.time) + ",")
        << (measured ? FormatNumber(e.measured_um) : "") << "," << FormatNumber(e.predicted_um)
        << "," << (check ? FormatNumber(e.threshold_um) : "") << ","
        << (check ? (e.valid ? "1" : "0") : "") << "," << CsvTextCell(e.message) << "\n";
    }
}

}  // namespace

std::string MonitorEventsCsv(const MonitorResult& r, const std::vector<std::string>& comments) {
  std::ostringstream o;
  for (const auto& c : WithComments(comments, "monitor events of " + r.run))
    o << "# " << SpreadsheetLine(c) << "\n";
  o << EventsHeader(r);
  EventRows(r, "", o);
  return o.str();
}

nlohmann::json MonitorJson(const MonitorResult& r, const MonitorOptions& o) {
  nlohmann::json strategies = nlohmann::json::array();
  for (const auto& s : r.strategies) {
    nlohmann::json events = nlohmann::json::array();
    for (const auto& e : s.events) events.push_back(EventJson(e));
    strategies.push_back(
        {{"rule", ToString(s.rule)},
         {"score", ErrorStatsJson(s.score)},
         {"checks", s.checks},
         {"invalid_checks", s.invalid_checks},
         {"measurements", s.measurements},
         {"recalibrations", s.recalibrations},
         {"stop_min", s.stop_min},
         {"stop_share", r.time_from_index ? nlohmann::json(nullptr) : nlohmann::json(s.stop_share)},
         {"final_coefficients",
          std::vector<double>(s.final_coefficients.data(),
                              s.final_coefficients.data() + s.final_coefficients.size())},
         {"events", events}});
  }
  std::vector<std::string> rules;
  for (UpdateRule u : o.rules) rules.push_back(ToString(u));
  nlohmann::json baselines = nlohmann::json::array();
  for (const auto& b : r.baselines)
    baselines.push_back({{"name", b.name}, {"score", ErrorStatsJson(b.score)}});
  return {{"schema", "whirl.drift_monitor"},
          {"schema_version", 2},
          {"baselines", baselines},
          {"strongest", r.Strongest()},
          {"run", r.run},
          {"error_column", r.error_column},
          {"model_kind", r.model_kind},
          {"time_unit", r.time_from_index ? "sample" : "min"},
          {"options",
           {{"check_every", o.check_every},
            {"refit_every", o.refit_every},
            {"refit_samples", o.refit_samples},
            {"stop_min_per_measurement", o.stop_min_per_measurement},
            {"threshold_um", o.threshold_um},
            {"threshold_sigma", o.threshold_sigma},
            {"noise_um", o.noise_um},
            {"seed", o.seed},
            {"prior_scale", o.prior_scale},
            {"estimate_drift", o.estimate_drift},
            {"start", o.start},
            {"score_from", o.score_from},
            {"score_to", o.score_to},
            {"reference", ToString(o.reference)},
            {"rules", rules}}},
          {"threshold_um", r.threshold_um},
          {"monitored_time", r.monitored_min},
          {"scored_rows", {r.score_begin, r.score_end}},
          {"none", ErrorStatsJson(r.none)},
          {"strategies", strategies},
          {"warnings", r.warnings}};
}

std::string FormatMonitor(const MonitorResult& r, const MonitorOptions& o) {
  const bool idx = r.time_from_index;
  const double to_h = idx ? 1.0 : 1.0 / 60.0;
  const std::string unit = idx ? "samples" : "h";
  std::ostringstream s;
  s << "run " << r.run << ", " << r.error_column << ", " << r.model_kind << " model; checks every "
    << MessageNumber(o.check_every) << (idx ? " samples" : " min") << ", threshold "
    << FormatDecimals(r.threshold_um, 2) << " um, " << o.refit_samples
    << " refit measurements every " << MessageNumber(o.refit_every) << (idx ? " samples" : " min")
    << ", " << MessageNumber(o.stop_min_per_measurement) << " min stop each"
    << (idx ? " (no recorded time: intervals count samples; stop share not computed)" : "")
    << "\n";
  s << "scored rows [" << r.score_begin << ", " << r.score_end
    << "): " << FormatDecimals(r.score_first_time * to_h, 2) << " to "
    << FormatDecimals(r.score_last_time * to_h, 2) << " " << unit
    << "\n";
  s << "rule      MAE um  RMSE um  max um  checks  invalid  recal  stop min  stop %\n";
  char buf[200];
  std::snprintf(buf, sizeof buf,
                "%-8s %7.2f %8.2f %7.2f       -        -      -         -       -\n", "none",
                r.none.mae_um, r.none.rmse_um, r.none.max_abs_um);
  s << buf;
  for (const auto& st : r.strategies) {
    std::snprintf(buf, sizeof buf, "%-8s %7.2f %8.2f %7.2f %7d %8d %6d %9.1f ",
                  ToString(st.rule).c_str(), st.score.mae_um, st.score.rmse_um, st.score.max_abs_um,
                  st.checks, st.invalid_checks, st.recalibrations, st.stop_min);
    s << buf << (idx ? "      -" : PadLeft(FormatDecimals(100.0 * st.stop_share, 2), 7)) << "\n";
  }
  for (const auto& b : r.baselines) {
    std::snprintf(buf, sizeof buf,
                  "%-8s %7.2f %8.2f %7.2f       -        -      -         -       -  (sensor-free)\n",
                  b.name.c_str(), b.score.mae_um, b.score.rmse_um, b.score.max_abs_um);
    s << buf;
  }
  s << "strongest (lowest MAE): " << r.Strongest() << "\n";
  for (const auto& st : r.strategies) {
    if (st.recalibrations == 0) continue;
    s << ToString(st.rule) << " updates:\n";
    for (const auto& e : st.events)
      if (e.kind == MonitorEvent::Kind::kUpdate || e.kind == MonitorEvent::Kind::kSkipped)
        s << "  " << FormatDecimals(e.time * to_h, 2) << " " << unit << ": " << e.message << "\n";
  }
  for (const auto& w : r.warnings) s << "warning: " << w << "\n";
  return s.str();
}

namespace {

// "data_2, data_3": the names of the days `which` (indices into w.days).
std::string DayNames(const WeekResult& w, const std::vector<int>& which) {
  std::string out;
  for (int d : which) out += (out.empty() ? "" : ", ") + w.days[static_cast<std::size_t>(d)].run;
  return out;
}

// One day's MAE [um] of the week's row `name` (none, a rule, a baseline), NaN where the day has
// no such row (the time baseline on the first day).
double DayMae(const MonitorResult& d, const std::string& name) {
  if (name == "none") return d.none.mae_um;
  for (const auto& st : d.strategies)
    if (ToString(st.rule) == name) return st.score.mae_um;
  for (const auto& b : d.baselines)
    if (b.name == name) return b.score.mae_um;
  return NAN;
}

// "4" when every checking rule (all but static) has the same value, else "4/5/4" in their order.
std::string PerRule(const MonitorResult& d,
                    const std::function<std::string(const StrategyResult&)>& f) {
  std::vector<std::string> v;
  for (const auto& st : d.strategies)
    if (st.rule != UpdateRule::kStatic) v.push_back(f(st));
  if (v.empty()) return "-";
  if (std::all_of(v.begin(), v.end(), [&v](const std::string& x) { return x == v.front(); }))
    return v.front();
  std::string out;
  for (const auto& x : v) out += (out.empty() ? "" : "/") + x;
  return out;
}

// The days as one table: day, samples, the MAE [um] of every row of the week (none, the rules,
// the baselines), the checking rules' checks, invalid checks and stop minutes, the day's
// strongest, the run; the variable-width columns last.
std::string DayTable(const WeekResult& w) {
  std::vector<std::string> names;
  for (const WeekRow& row : w.week) names.push_back(row.name);
  std::string rules;
  for (const auto& st : w.days.front().strategies)
    if (st.rule != UpdateRule::kStatic) rules += (rules.empty() ? "" : "/") + ToString(st.rule);
  std::ostringstream s;
  s << "per day, MAE [um] of each row (" << kPreviousRunBaseline
    << ": drift fit at its defaults redone on the previous day, the given model on the first;\n"
       "time: sensor-free warm-up fitted on the previous day; -: not run that day), then the "
       "checks, invalid checks\nand stop [min] of the checking rules "
    << rules << " (one number when they agree, else each in that order):\n";
  const auto width = [](const std::string& name) { return std::max<std::size_t>(7, name.size()); };
  const auto checks = [](const StrategyResult& r) { return std::to_string(r.checks); };
  const auto invalid = [](const StrategyResult& r) { return std::to_string(r.invalid_checks); };
  const auto stop = [](const StrategyResult& r) { return FormatDecimals(r.stop_min, 0); };
  s << "  day  samples";
  for (const auto& n : names) s << "  " << PadLeft(n, width(n));
  s << "  checks  invalid  stop min  strongest     run\n";
  for (std::size_t i = 0; i < w.days.size(); ++i) {
    const MonitorResult& d = w.days[i];
    s << "  " << PadLeft(std::to_string(i + 1), 3) << "  " << PadLeft(std::to_string(d.samples), 7);
    for (const auto& n : names)
      s << "  " << PadLeft(FormatDecimalsOr(DayMae(d, n), 2, "-"), width(n));
    const std::string strongest = d.Strongest();
    s << "  " << PadLeft(PerRule(d, checks), 6) << "  " << PadLeft(PerRule(d, invalid), 7) << "  "
      << PadLeft(PerRule(d, stop), 8) << "  " << strongest
      << std::string(strongest.size() < 12 ? 12 - strongest.size() : 1, ' ') << "  " << d.run
      << "\n";
  }
  return s.str();
}

}  // namespace

std::string FormatWeek(const WeekResult& w, const MonitorOptions& o) {
  std::ostringstream s;
  const bool idx = w.days.front().time_from_index;
  s << "production week of " << w.days.size() << " day(s), " << w.days.front().error_column
    << ": checks every " << MessageNumber(o.check_every) << (idx ? " samples" : " min")
    << " from each day's start, " << o.refit_samples
    << " refit measurements; each rule carries its coefficients (and the bayes covariance) "
       "from day to day\n";
  s << DayTable(w);
  s << "week           days  MAE um  RMSE um  measurements  stop min\n";
  for (const WeekRow& row : w.week) {
    char buf[160];
    std::snprintf(buf, sizeof buf, "  %-12s %4d %7.2f %8.2f", row.name.c_str(), row.days,
                  row.score.mae_um, row.score.rmse_um);
    s << buf;
    for (std::size_t i = 0; i < w.days.front().strategies.size(); ++i)
      if (ToString(w.days.front().strategies[i].rule) == row.name)
        s << PadLeft(std::to_string(w.measurements[i]), 14) << PadLeft(FormatDecimals(w.stop_min[i], 0), 10);
    s << "\n";
  }
  s << "strongest over the week (lowest MAE among the rows covering all " << w.days.size()
    << " days): " << w.strongest << "\n";
  for (const WeekPartial& p : w.partial)
    s << p.name << " covers " << p.days.size() << " of " << w.days.size() << " days (" << DayNames(w, p.days)
      << "): not ranked; over those days " << p.name << " " << FormatDecimals(p.mae_um, 2)
      << " um, the strongest row covering every day " << p.strongest << " "
      << FormatDecimals(p.strongest_mae_um, 2) << " um\n";
  return s.str();
}

nlohmann::json WeekJson(const WeekResult& w, const MonitorOptions& o) {
  nlohmann::json days = nlohmann::json::array();
  for (const auto& d : w.days) days.push_back(MonitorJson(d, o));
  nlohmann::json week = nlohmann::json::array();
  for (const WeekRow& row : w.week)
    week.push_back({{"name", row.name}, {"score", ErrorStatsJson(row.score)}, {"days", row.days}});
  nlohmann::json partial = nlohmann::json::array();
  for (const WeekPartial& p : w.partial) {
    std::vector<std::string> names;
    for (int d : p.days) names.push_back(w.days[static_cast<std::size_t>(d)].run);
    partial.push_back({{"name", p.name},
                       {"days", names},
                       {"mae_um", p.mae_um},
                       {"strongest", p.strongest},
                       {"strongest_mae_um", p.strongest_mae_um}});
  }
  return {{"schema", "whirl.drift_monitor_week"},
          {"schema_version", 1},
          {"days", days},
          {"week", week},
          {"measurements", w.measurements},
          {"stop_min", w.stop_min},
          {"strongest", w.strongest},
          {"partial", partial}};
}

std::string WeekTimelineCsv(const WeekResult& w, const std::vector<std::string>& comments) {
  const MonitorResult& first = w.days.front();
  std::vector<UpdateRule> rules;
  for (const auto& s : first.strategies) rules.push_back(s.rule);
  std::vector<std::string> c = comments;
  for (std::size_t d = 0; d < w.days.size(); ++d)
    c.push_back("day " + std::to_string(d + 1) + ": " + w.days[d].run);
  std::string out = MonitorTimelineHeader(
      first.time_from_index, rules, WithComments(c, "monitor timeline of a week, day by day"), true);
  for (std::size_t d = 0; d < w.days.size(); ++d) {
    const MonitorResult& r = w.days[d];
    std::vector<double> predicted(r.strategies.size());
    for (Eigen::Index k = 0; k < r.measured_um.size(); ++k) {
      for (std::size_t i = 0; i < predicted.size(); ++i)
        predicted[i] = r.strategies[i].predicted_um(k);
      AppendTimelineRow(r.time[static_cast<std::size_t>(k)], r.measured_um(k), predicted, &out,
                        static_cast<int>(d + 1));
    }
  }
  return out;
}

TimelineSink::TimelineSink(const MonitorOptions& o, bool time_from_index,
                           std::vector<std::string> header_comments,
                           std::vector<StreamedFile*> files, int day, bool write_header)
    : rules_(ReplayedRules(o)), time_from_index_(time_from_index),
      comments_(std::move(header_comments)), files_(std::move(files)), day_(day),
      header_(write_header) {}

void TimelineSink::Flush() {
  for (StreamedFile* f : files_) f->Append(text_);
  text_.clear();
}

void TimelineSink::Add(const MonitorSample& s) {
  if (s.index == 0) {
    if (header_ && !files_.empty())
      text_ = MonitorTimelineHeader(time_from_index_, rules_, comments_, day_ > 0);
    plot_ = std::make_unique<M4Decimator>(static_cast<int>(1 + 2 * rules_.size()), s.first_time,
                                          s.last_time);
  }
  if (!files_.empty()) {
    AppendTimelineRow(s.time, s.measured_um, s.predicted_um, &text_, day_);
    if (text_.size() >= (1u << 20)) Flush();
  }
  values_.assign(1, s.measured_um);
  values_.insert(values_.end(), s.predicted_um.begin(), s.predicted_um.end());
  for (double p : s.predicted_um) values_.push_back(s.measured_um - p);
  plot_->Add(s.index, s.time, values_.data());
}

void TimelineSink::Finish(MonitorResult* r) {
  Flush();
  if (!plot_ || r == nullptr) return;
  plot_->Finish();
  const std::size_t n = plot_->rows().size(), q = rules_.size(), w = 1 + 2 * q;
  r->rows_kept = plot_->rows();
  r->time = plot_->x();
  r->measured_um.resize(static_cast<Eigen::Index>(n));
  for (auto& st : r->strategies) st.predicted_um.resize(static_cast<Eigen::Index>(n));
  for (std::size_t i = 0; i < n; ++i) {
    const double* v = plot_->values().data() + i * w;
    r->measured_um(static_cast<Eigen::Index>(i)) = v[0];
    for (std::size_t j = 0; j < q && j < r->strategies.size(); ++j)
      r->strategies[j].predicted_um(static_cast<Eigen::Index>(i)) = v[1 + j];
  }
  r->measurement_noise_um.resize(0);
}

std::string WeekEventsCsv(const WeekResult& w, const std::vector<std::string>& comments) {
  std::ostringstream o;
  for (const auto& c : WithComments(comments, "monitor events of a week, day by day"))
    o << "# " << SpreadsheetLine(c) << "\n";
  if (!w.days.empty()) o << "day," << EventsHeader(w.days.front());  // the column names once
  for (const auto& day : w.days) EventRows(day, CsvTextCell(day.run) + ",", o);
  return o.str();
}

namespace {

// checks.csv: marker data per rule (gnuplot index blocks, CSV like the timeline): time, measured,
// 1 for an invalid check or a refit measurement, 0 for a valid check.
std::string ChecksCsv(const MonitorResult& r) {
  std::ostringstream marks;
  marks << "# one block per rule in the order of timeline.csv: time,measured_um,invalid\n";
  for (const auto& st : r.strategies) {
    marks << "# " << ToString(st.rule) << "\n";
    for (const auto& e : st.events)
      if (e.kind == MonitorEvent::Kind::kCheck || e.kind == MonitorEvent::Kind::kRefitMeasurement)
        marks << FormatNumber(e.time) << "," << FormatNumber(e.measured_um) << ","
              << (e.kind == MonitorEvent::Kind::kCheck && e.valid ? 0 : 1) << "\n";
    marks << FormatNumber(r.first_time) << ",0,-1\n\n\n";  // sentinel: no block is empty
  }
  return marks.str();
}

using report::Col;
using report::SeriesKind;

// The monitor's figure (<prefix>monitor.gp/.png): the measured error and every rule's model over
// time with its checks (open: valid, filled: invalid checks and refit measurements) and the
// start of monitoring (dashed), and the residuals below. Each rule in its look of
// core/plot_style.h, its checks in its colour; `prefix` names the files of one day of a week.
report::Figure MonitorFigure(const MonitorResult& r, const std::string& prefix) {
  const double per = r.time_from_index ? 1.0 : 60.0;
  const std::size_t q = r.strategies.size();
  const std::string timeline = prefix + "plot_timeline.csv", checks = prefix + "checks.csv";
  report::Panel top, bottom;
  top.title = "run " + r.run + ": measured " + r.error_column + " and the models";
  top.ylabel = "thermal error [um]";
  bottom.title = "residual (measured - model)";
  bottom.ylabel = "residual [um]";
  for (report::Panel* p : {&top, &bottom}) {
    p->xlabel = r.time_from_index ? "sample" : "time [h]";
    p->x_marks = {(r.last_time - r.monitored_min) / per};
  }
  // Each rule's +-1 sd band (the model's training residual std) under the lines.
  const double sd = r.training_residual_std_um;
  for (std::size_t i = 0; i < q && sd > 0; ++i) {
    const std::string rule = ToString(r.strategies[i].rule);
    const int k = static_cast<int>(i) + 3;
    top.series.push_back(report::SdBand(timeline, Col(1, per), k, sd, rule,
                                        rule + " +- 1 sd (" + FormatDecimals(sd, 2) + " um)"));
  }
  top.series.push_back({timeline, -1, {Col(1, per), Col(2)}, SeriesKind::kLine, "measured", "", 1.5,
                        false, "measured"});
  for (std::size_t i = 0; i < q; ++i) {
    const std::string rule = ToString(r.strategies[i].rule);
    const int k = static_cast<int>(i);
    // A rule that never left an earlier one's prediction is drawn with open circles and its
    // legend says so: coinciding lines stay distinguishable.
    std::string same;
    const Eigen::VectorXd& v = r.strategies[i].predicted_um;
    for (std::size_t e = 0; e < i && same.empty(); ++e) {
      const Eigen::VectorXd& u = r.strategies[e].predicted_um;
      if (u.size() == v.size() && v.size() > 0 &&
          (u - v).cwiseAbs().maxCoeff() <= 1e-9 * (1 + v.cwiseAbs().maxCoeff()))
        same = ToString(r.strategies[e].rule);
    }
    const std::string title = rule + (same.empty() ? "" : " (the same as " + same + ")");
    report::Series line{timeline, -1, {Col(1, per), Col(k + 3)}, SeriesKind::kLine, rule, "", 1.5,
                        false, title};
    line.markers = !same.empty();
    top.series.push_back(line);
    line.columns = {Col(1, per), Col(k + 3 + static_cast<int>(q))};
    bottom.series.push_back(line);
  }
  for (std::size_t i = 1; i < q; ++i) {
    const std::string rule = ToString(r.strategies[i].rule);
    for (const int invalid : {0, 1}) {
      report::Column y = Col(2);
      y.only_if_column = 3;
      y.only_if_value = invalid;
      report::Series s{checks, static_cast<int>(i), {Col(1, per), y},
                       invalid ? SeriesKind::kPoints : SeriesKind::kOpenPoints, "", "", 1.5, false,
                       ""};
      const SeriesStyle* look = FindSeriesStyle(rule);
      s.colour = look ? std::string(look->colour) : "#aaaaaa";
      top.series.push_back(std::move(s));
    }
  }
  report::Figure f;
  f.stem = prefix + "monitor";
  f.alt = "monitor timeline of " + r.run;
  f.width_px = 1000;
  f.height_px = 700;
  f.panels = {top, bottom};
  return f;
}

// The rules' table: MAE, RMSE and max per rule, no compensation and the sensor-free baselines,
// with checks, invalid checks, recalibrations and stop time.
report::Table MonitorTable(const MonitorResult& r) {
  report::Table t;
  t.series_rows = true;
  t.header = {"rule", "MAE [um]", "RMSE [um]", "max [um]", "checks", "invalid", "recalibrations",
              "stop [min]", "stop [%]"};
  const auto stats = [](const ErrorStats& s) {
    return std::vector<report::Cell>{FormatDecimals(s.mae_um, 2), FormatDecimals(s.rmse_um, 2),
                                     FormatDecimals(s.max_abs_um, 2)};
  };
  report::Cell none_name("none (no compensation)");
  none_name.not_plotted = true;
  std::vector<report::Cell> none{none_name};
  for (auto& c : stats(r.none)) none.push_back(c);
  none.insert(none.end(), {"-", "-", "-", "-", "-"});
  t.rows.push_back(none);
  for (const auto& st : r.strategies) {
    std::vector<report::Cell> row{ToString(st.rule)};
    for (auto& c : stats(st.score)) row.push_back(c);
    row.insert(row.end(),
               {std::to_string(st.checks), std::to_string(st.invalid_checks),
                std::to_string(st.recalibrations), FormatDecimals(st.stop_min, 1),
                r.time_from_index ? std::string("-") : FormatDecimals(100.0 * st.stop_share, 2)});
    if (ToString(st.rule) == r.Strongest()) t.highlight.push_back(t.rows.size());
    t.rows.push_back(std::move(row));
  }
  for (const auto& b : r.baselines) {
    report::Cell name(b.name + " (sensor-free, not drawn)");
    name.not_plotted = true;
    std::vector<report::Cell> row{name};
    for (auto& c : stats(b.score)) row.push_back(c);
    row.insert(row.end(), {"-", "-", "-", "-", "-"});
    t.rows.push_back(std::move(row));
  }
  return t;
}

// The week: per row (none, the rules, the baselines) the MAE and RMSE over the days it covers,
// and for the rules the measurements and stop time; the strongest over the week bold.
report::Table WeekTable(const WeekResult& w) {
  report::Table t;
  t.series_rows = true;
  t.header = {"row", "days", "MAE [um]", "RMSE [um]", "measurements", "stop [min]"};
  const auto& rules = w.days.front().strategies;
  for (const WeekRow& row : w.week) {
    std::size_t rule = rules.size();
    for (std::size_t i = 0; i < rules.size(); ++i)
      if (ToString(rules[i].rule) == row.name) rule = i;
    report::Cell name(row.name);
    name.not_plotted = rule == rules.size();  // none and the baselines are not drawn
    if (row.name == w.strongest) t.highlight.push_back(t.rows.size());
    t.rows.push_back({name, std::to_string(row.days), FormatDecimals(row.score.mae_um, 2),
                      FormatDecimals(row.score.rmse_um, 2),
                      rule < rules.size() ? std::to_string(w.measurements[rule]) : "-",
                      rule < rules.size() ? FormatDecimals(w.stop_min[rule], 0) : "-"});
  }
  t.caption = "Each rule carries its coefficients (and the bayes covariance) from day to day; "
              "previous run = drift fit at its defaults redone on the previous day (the given "
              "model on the first); time = sensor-free warm-up fitted on the previous day. Bold: "
              "the strongest over the week (lowest MAE among the rows covering every day).";
  return t;
}

// What the monitor ran with: the model, the check interval, the threshold, the refits.
std::string SettingsText(const MonitorResult& r, const MonitorOptions& o) {
  const bool idx = r.time_from_index;
  const std::string every = idx ? " samples" : " min";
  return r.error_column + ", " + r.model_kind + " model; checks every " +
         MessageNumber(o.check_every) + every + ", threshold " + FormatDecimals(r.threshold_um, 2) +
         " um, " + std::to_string(o.refit_samples) + " refit measurements every " +
         MessageNumber(o.refit_every) + every + ", " + MessageNumber(o.stop_min_per_measurement) +
         " min stop each" +
         (idx ? " (no recorded time: intervals count samples; stop share not computed)" : "");
}

// The scored part of a run: "6.00 to 14.50 h" (or samples).
std::string ScoredSpan(const MonitorResult& r) {
  const double to_h = r.time_from_index ? 1.0 : 1.0 / 60.0;
  return FormatDecimals(r.score_first_time * to_h, 2) + " to " +
         FormatDecimals(r.score_last_time * to_h, 2) + (r.time_from_index ? " samples" : " h");
}

// The week's days in one table: the scored span, the MAE of no compensation and of each rule,
// the day's strongest row (rules and sensor-free baselines).
report::Table DaysTable(const WeekResult& w) {
  report::Table t;
  t.header = {"day", "run", "scored", "none: MAE [um]"};
  const std::size_t q = w.days.front().strategies.size();
  for (const auto& st : w.days.front().strategies)
    t.header.push_back(ToString(st.rule) + ": MAE [um]");
  t.header.push_back("strongest");
  for (std::size_t d = 0; d < w.days.size(); ++d) {
    const MonitorResult& r = w.days[d];
    std::vector<report::Cell> row = {std::to_string(d + 1), r.run, ScoredSpan(r),
                                     FormatDecimals(r.none.mae_um, 2)};
    for (std::size_t i = 0; i < q; ++i)
      row.push_back(i < r.strategies.size() ? FormatDecimals(r.strategies[i].score.mae_um, 2)
                                            : "-");
    row.push_back(r.Strongest());
    t.rows.push_back(std::move(row));
  }
  t.caption =
      "MAE over each day's scored rows; strongest: the lowest MAE of the day among no "
      "compensation, the rules and the sensor-free baselines (each day's table below).";
  return t;
}

// One run's part of the page: what was run (`with_settings`: a week states them once above its
// days), the table, the updates, the figure, the data.
std::vector<report::Block> MonitorBlocks(const MonitorResult& r, const MonitorOptions& o,
                                         const std::string& prefix, bool with_settings = true) {
  using report::MakeBlock;
  const bool idx = r.time_from_index;
  const double to_h = idx ? 1.0 : 1.0 / 60.0;
  const std::string unit = idx ? " samples" : " h";
  std::vector<report::Block> b;
  if (with_settings)
    b.push_back(MakeBlock(report::Paragraph{
        {report::Text("Run " + r.run + ", " + SettingsText(r, o) + ". Scored rows [" +
                      std::to_string(r.score_begin) + ", " + std::to_string(r.score_end) + "): " +
                      ScoredSpan(r) + ". Strongest (lowest MAE, bold): " + r.Strongest() + ".")}}));
  b.push_back(MakeBlock(MonitorTable(r)));
  report::List updates;
  updates.tone = report::Tone::kSmall;
  for (const auto& st : r.strategies)
    for (const auto& e : st.events)
      if (e.kind == MonitorEvent::Kind::kUpdate || e.kind == MonitorEvent::Kind::kSkipped)
        updates.items.push_back({report::Bold(ToString(st.rule)),
                                 report::Text(" at " + FormatDecimals(e.time * to_h, 2) + unit +
                                              ": " + e.message)});
  if (!updates.items.empty()) {
    b.push_back(MakeBlock(report::Paragraph{{report::Text("Recalibrations:")}}));
    b.push_back(MakeBlock(updates));
  }
  for (const auto& w : r.warnings)
    b.push_back(MakeBlock(report::Paragraph{{report::Text("warning: " + w)}, report::Tone::kWarn}));
  b.push_back(MakeBlock(MonitorFigure(r, prefix)));
  b.push_back(MakeBlock(report::Paragraph{
      {report::Text("The dashed vertical line: monitoring starts; open circles: valid checks, "
                    "filled: invalid checks and refit measurements, in their rule's colour; the "
                    "shaded bands: each rule's prediction +- 1 sd, the sd the model's training "
                    "residual std (" +
                    FormatDecimals(r.training_residual_std_um, 2) +
                    " um, from its training runs, not from this run). Data: "),
       report::Link(prefix + "timeline.csv", prefix + "timeline.csv"), report::Text(", "),
       report::Link(prefix + "events.csv", prefix + "events.csv"),
       report::Text(" (every check and update with its reason), "),
       report::Link(prefix + "monitor.gp", prefix + "monitor.gp"), report::Text(".")},
      report::Tone::kSmall}));
  return b;
}

}  // namespace

namespace {

// plot_timeline.csv: the rows the plot needs (the series as given when already cut).
std::string PlotTimelineCsv(const MonitorResult& r, const std::vector<std::string>& provenance) {
  std::vector<std::string> c{"the rows of timeline.csv a plot needs (M4: first, last, minimum and "
                             "maximum of every series per pixel column), " +
                             std::to_string(r.rows_kept.empty() ? r.measured_um.size()
                                                                : static_cast<Eigen::Index>(r.rows_kept.size())) +
                             " of " + std::to_string(r.samples) + " rows"};
  c.insert(c.end(), provenance.begin(), provenance.end());
  return MonitorTimelineCsv(r.rows_kept.empty() ? PlotRows(r) : r, c);
}

// The data of one run's part of the page, each file's name after `prefix`: its timeline (or
// the one the caller streamed, `ready`), the plot's rows, the events, the checks.
void AddRunFiles(OutputDir& files, const MonitorResult& r,
                 const std::vector<std::string>& provenance, const std::string& prefix,
                 const fs::path& ready) {
  if (ready.empty())
    files.Add(prefix + "timeline.csv", MonitorTimelineCsv(r, provenance));
  else
    files.AddReady(prefix + "timeline.csv", ready);
  files.Add(prefix + "plot_timeline.csv", PlotTimelineCsv(r, provenance));
  files.Add(prefix + "events.csv", MonitorEventsCsv(r, provenance));
  files.Add(prefix + "checks.csv", ChecksCsv(r));
}

// Renders the page beside its data and commits the directory.
MonitorReportResult RenderAndCommit(const report::Document& doc, OutputDir& files,
                                    const std::string& gnuplot, const AlsoWrite& also,
                                    const std::vector<ReadyFile>& also_ready) {
  MonitorReportResult out;
  report::RenderOptions ro;
  ro.gnuplot = gnuplot;
  out.warnings = report::RenderReport(doc, files, ro).warnings;
  files.Commit(also, also_ready);
  out.index_html = files.path() / "index.html";
  return out;
}

}  // namespace

MonitorReportResult WriteMonitorReport(const fs::path& dir, const MonitorResult& r,
                                       const MonitorOptions& o,
                                       const std::vector<std::string>& provenance,
                                       const std::string& gnuplot, const AlsoWrite& also) {
  OutputDir files(dir, "report directory");
  return WriteMonitorReport(files, r, o, provenance, gnuplot, also, {}, {});
}

MonitorReportResult WriteMonitorReport(OutputDir& files, const MonitorResult& r,
                                       const MonitorOptions& o,
                                       const std::vector<std::string>& provenance,
                                       const std::string& gnuplot, const AlsoWrite& also,
                                       const std::vector<ReadyFile>& also_ready,
                                       const fs::path& timeline_ready) {
  AddRunFiles(files, r, provenance, "", timeline_ready);
  report::Document doc;
  doc.title = "whirl: on-line check and recalibration of " + r.error_column + " on " + r.run;
  doc.provenance = provenance;
  doc.Add(DriftLoadBox(r.model_kind, r.error_column, {}));
  doc.Add(MonitorBlocks(r, o, ""));
  return RenderAndCommit(doc, files, gnuplot, also, also_ready);
}

MonitorReportResult WriteWeekReport(const fs::path& dir, const WeekResult& w,
                                    const MonitorOptions& o,
                                    const std::vector<std::string>& provenance,
                                    const std::string& gnuplot, const AlsoWrite& also) {
  OutputDir files(dir, "report directory");
  return WriteWeekReport(files, w, o, provenance, gnuplot, also, {}, {}, {});
}

MonitorReportResult WriteWeekReport(OutputDir& files, const WeekResult& w, const MonitorOptions& o,
                                    const std::vector<std::string>& provenance,
                                    const std::string& gnuplot, const AlsoWrite& also,
                                    const std::vector<ReadyFile>& also_ready,
                                    const std::vector<fs::path>& day_ready,
                                    const fs::path& week_ready) {
  if (week_ready.empty())
    files.Add("week_timeline.csv", WeekTimelineCsv(w, provenance));
  else
    files.AddReady("week_timeline.csv", week_ready);
  files.Add("week_events.csv", WeekEventsCsv(w, provenance));
  report::Document doc;
  doc.title = "whirl: a production week of " + w.days.front().error_column + ", " +
              std::to_string(w.days.size()) + " days";
  doc.provenance = provenance;
  doc.Add(DriftLoadBox(w.days.front().model_kind, w.days.front().error_column, {}));
  doc.Add(report::Heading{2, "Week", ""});
  doc.Add(WeekTable(w));
  for (const WeekPartial& p : w.partial) {
    std::string days;
    for (int d : p.days) days += (days.empty() ? "" : ", ") + w.days[static_cast<std::size_t>(d)].run;
    doc.Say(p.name + " covers " + std::to_string(p.days.size()) + " of " +
                std::to_string(w.days.size()) + " days (" + days + "): not ranked; over those days " +
                p.name + " " + FormatDecimals(p.mae_um, 2) + " um, the strongest row covering every day " +
                p.strongest + " " + FormatDecimals(p.strongest_mae_um, 2) + " um.",
            report::Tone::kSmall);
  }
  doc.Say("Every day: " + SettingsText(w.days.front(), o) + ".");
  doc.Add(report::Heading{3, "Days", ""}).Add(DaysTable(w));
  doc.Add(report::Paragraph{{report::Text("Data: "),
                             report::Link("week_timeline.csv", "week_timeline.csv"),
                             report::Text(" (every day, a day column first), "),
                             report::Link("week_events.csv", "week_events.csv"), report::Text(".")},
                            report::Tone::kSmall});
  for (std::size_t d = 0; d < w.days.size(); ++d) {
    const MonitorResult& r = w.days[d];
    const std::string prefix = "day" + std::to_string(d + 1) + "_";
    AddRunFiles(files, r, provenance, prefix, d < day_ready.size() ? day_ready[d] : fs::path());
    doc.Add(report::Heading{2, "Day " + std::to_string(d + 1) + ": " + r.run, ""});
    doc.Add(MonitorBlocks(r, o, prefix, false));
  }
  return RenderAndCommit(doc, files, gnuplot, also, also_ready);
}

}  // namespace whirl::drift
