#pragma once
// Output documents of the on-line check (drift/monitor.h MonitorRun), built here once; the
// command line only writes or prints them: the timeline and events CSV, the JSON document, the
// text table and the HTML report with its plot.
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "core/decimate.h"
#include "core/output_dir.h"
#include "drift/monitor.h"

namespace whirl::drift {

/// Per sample: time_min (or sample), measured_um, none_um (0), <rule>_um predictions, and
/// <rule>_residual_um.
std::string MonitorTimelineCsv(const MonitorResult& r, const std::vector<std::string>& comments);
/// The same CSV row by row (a streamed replay): its comments and header (`day_column`: the week's
/// first column) ...
std::string MonitorTimelineHeader(bool time_from_index, const std::vector<UpdateRule>& rules,
                                  const std::vector<std::string>& comments,
                                  bool day_column = false);
/// ... and one row (`day` > 0: the week's day column first).
void AppendTimelineRow(double time, double measured, const std::vector<double>& predicted,
                       std::string* out, int day = 0);
/// The result with its per-sample series cut to the rows a plot needs (M4, core/decimate.h):
/// first, last, minimum and maximum of the measured error, each prediction and each residual per
/// pixel column; rows_kept names them.
MonitorResult PlotRows(const MonitorResult& r, int columns = kPlotColumns);

/// The per-sample outputs of a streamed replay (MonitorFile's sink): the timeline CSV rows go
/// into `files` (the --timeline file, the report's timeline.csv; with `day` > 0 the week's
/// timeline with its day column) as they come, and the rows a plot needs are kept (M4). Fixed
/// memory but for the plot's rows (a few thousand).
class TimelineSink {
 public:
  /// `header_comments`: the CSV's comment lines; `files` may be empty (the plot's rows only).
  TimelineSink(const MonitorOptions& o, bool time_from_index,
               std::vector<std::string> header_comments, std::vector<StreamedFile*> files,
               int day = 0, bool write_header = true);
  void Add(const MonitorSample& s);
  /// Flushes the rows still buffered and sets r's series to the plot's rows (rows_kept).
  void Finish(MonitorResult* r);

 private:
  void Flush();
  std::vector<UpdateRule> rules_;
  bool time_from_index_;
  std::vector<std::string> comments_;
  std::vector<StreamedFile*> files_;
  int day_;
  bool header_;
  std::string text_;
  std::unique_ptr<M4Decimator> plot_;
  std::vector<double> values_;
};
/// Every event of every rule: rule, kind, sample, time, measured_um, predicted_um,
/// threshold_um, valid, message.
std::string MonitorEventsCsv(const MonitorResult& r, const std::vector<std::string>& comments);
nlohmann::json MonitorJson(const MonitorResult& r, const MonitorOptions& o);
/// The week: a table of one row per day (day, samples, the MAE [um] of none, each rule and the
/// baselines, the checking rules' checks, invalid checks and stop minutes - one number when they
/// agree -, the day's strongest, the run); then the week's MAE / RMSE per row, measurements and
/// stop time totalled, and the strongest. JSON schema whirl.drift_monitor_week v1.
std::string FormatWeek(const WeekResult& w, const MonitorOptions& o);
nlohmann::json WeekJson(const WeekResult& w, const MonitorOptions& o);
/// The week's timeline: every day's MonitorTimelineCsv rows with a first column `day` (1, 2, ...;
/// the comment lines name each day's run).
std::string WeekTimelineCsv(const WeekResult& w, const std::vector<std::string>& comments);
/// The week's events: every day's MonitorEventsCsv rows with a first column `day` (the run).
std::string WeekEventsCsv(const WeekResult& w, const std::vector<std::string>& comments);
std::string FormatMonitor(const MonitorResult& r, const MonitorOptions& o);

struct MonitorReportResult {
  std::filesystem::path index_html;
  std::vector<std::string> warnings;
};
/// Files written together with a report, outside its directory: (path, contents).
using AlsoWrite = std::vector<std::pair<std::filesystem::path, std::string>>;

/// HTML page (a report document rendered by core/report_render.h): the "load onto the control"
/// box (drift/load_box.h), the rules' table (the strongest bold), the recalibrations, and a plot
/// of measured and predicted error per rule with the checks and recalibrations marked, and the
/// residuals (gnuplot; skipped with a warning when absent), beside the timeline and events CSV it is drawn from. `dir` follows the
/// output-directory rule of core/output_dir.h; the page, its files and `also` (e.g. the
/// --timeline and --events files) are written all-or-nothing.
MonitorReportResult WriteMonitorReport(const std::filesystem::path& dir, const MonitorResult& r,
                                       const MonitorOptions& o,
                                       const std::vector<std::string>& provenance,
                                       const std::string& gnuplot = "gnuplot",
                                       const AlsoWrite& also = {});
/// The same into an output directory opened before a streamed replay: `timeline_ready` (not
/// empty) is the run's whole timeline.csv already written (a StreamedFile inside files.Staging(),
/// finished), and r's series are the plot's rows; `also_ready`: finished files outside it (the
/// --timeline file). The plot reads plot_timeline.csv (PlotRows) in both forms.
MonitorReportResult WriteMonitorReport(OutputDir& files, const MonitorResult& r,
                                       const MonitorOptions& o,
                                       const std::vector<std::string>& provenance,
                                       const std::string& gnuplot, const AlsoWrite& also,
                                       const std::vector<ReadyFile>& also_ready,
                                       const std::filesystem::path& timeline_ready);

/// The week's page: the week table (FormatWeek) and per day its table, plot and files
/// (day<k>_timeline.csv, day<k>_events.csv, day<k>_monitor.gp/.png), with week_timeline.csv and
/// week_events.csv; the same rules as WriteMonitorReport (all-or-nothing, `also` included).
MonitorReportResult WriteWeekReport(const std::filesystem::path& dir, const WeekResult& w,
                                    const MonitorOptions& o,
                                    const std::vector<std::string>& provenance,
                                    const std::string& gnuplot = "gnuplot",
                                    const AlsoWrite& also = {});
/// The same for streamed days: `day_ready` the days' timeline.csv files and `week_ready` the
/// week's, already written inside files.Staging() (empty: built from the series), the days'
/// series the plots' rows.
MonitorReportResult WriteWeekReport(OutputDir& files, const WeekResult& w, const MonitorOptions& o,
                                    const std::vector<std::string>& provenance,
                                    const std::string& gnuplot, const AlsoWrite& also,
                                    const std::vector<ReadyFile>& also_ready,
                                    const std::vector<std::filesystem::path>& day_ready,
                                    const std::filesystem::path& week_ready);

}  // namespace whirl::drift
