#pragma once
// Output documents of the on-line check (drift/monitor.h MonitorRun), built here once; the
// command line only writes or prints them: the timeline and events CSV, the JSON document, the
// text table and the HTML report with its plot.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "drift/monitor.h"

namespace whirl::drift {

/// Per sample: time_min (or sample), measured_um, none_um (0), <rule>_um predictions, and
/// <rule>_residual_um.
std::string MonitorTimelineCsv(const MonitorResult& r, const std::vector<std::string>& comments);
/// Every event of every rule: rule, kind, sample, time, measured_um, predicted_um,
/// threshold_um, valid, message.
std::string MonitorEventsCsv(const MonitorResult& r, const std::vector<std::string>& comments);
nlohmann::json MonitorJson(const MonitorResult& r, const MonitorOptions& o);
/// The week: per day the table of none, each rule and the baselines (MAE [um]), checks and stop
/// minutes; then the week's MAE / RMSE per row, measurements and stop time totalled, and the
/// strongest. JSON schema whirl.drift_monitor_week v1.
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

/// HTML page with the table and a plot of measured and predicted error per rule with the checks
/// and recalibrations marked, and the residuals (gnuplot via RunProgram; skipped with a warning
/// when absent), beside the timeline and events CSV it is drawn from. `dir` follows the
/// output-directory rule of core/output_dir.h; the page, its files and `also` (e.g. the
/// --timeline and --events files) are written all-or-nothing.
MonitorReportResult WriteMonitorReport(const std::filesystem::path& dir, const MonitorResult& r,
                                       const MonitorOptions& o,
                                       const std::vector<std::string>& provenance,
                                       const std::string& gnuplot = "gnuplot",
                                       const AlsoWrite& also = {});

/// The week's page: the week table (FormatWeek) and per day its table, plot and files
/// (day<k>_timeline.csv, day<k>_events.csv, day<k>_monitor.gp/.png), with week_timeline.csv and
/// week_events.csv; the same rules as WriteMonitorReport (all-or-nothing, `also` included).
MonitorReportResult WriteWeekReport(const std::filesystem::path& dir, const WeekResult& w,
                                    const MonitorOptions& o,
                                    const std::vector<std::string>& provenance,
                                    const std::string& gnuplot = "gnuplot",
                                    const AlsoWrite& also = {});

}  // namespace whirl::drift
