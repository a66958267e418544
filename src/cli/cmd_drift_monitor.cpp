// whirl drift monitor: replay of the on-line model check with a check bar and the recalibration
// rules (Liu et al.'s check-bar patent) on a logged run (src/product/drift/monitor.h).
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/common.h"
#include "cli/drift_args.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "drift/monitor_report.h"
#include "drift/run_file.h"

namespace whirl::cli {

namespace {

struct MonitorArgs {
  std::string model, run, reference = "run-start", timeline, events, out_dir;
  std::vector<std::string> days, updates{"patent", "bayes", "offset"};
  // Intervals with their unit in the flag's name; NaN: not given.
  double check_every_min = std::numeric_limits<double>::quiet_NaN(),
         check_every_samples = std::numeric_limits<double>::quiet_NaN(),
         refit_every_min = std::numeric_limits<double>::quiet_NaN(),
         refit_every_samples = std::numeric_limits<double>::quiet_NaN(),
         start_min = std::numeric_limits<double>::quiet_NaN(),
         start_samples = std::numeric_limits<double>::quiet_NaN();
  TimeAxisFlags check_flags, refit_flags, start_flags;
  std::vector<double> score_rows{0.0, 1.0};
  bool no_drift_estimate = false;
  drift::MonitorOptions o;
  bool json = false, progress = false;
};

// One quantity on the run's time axis: --<name>-min, --<name>-samples and the old spelling
// --<name> (ChooseTimeAxis picks the flag that fits the run). Help: "<what> [min] (default
// <min_default>)" and "<what> [samples], for runs without recorded time (default ...)".
struct MonitorTimeOption {
  const char* name;
  const char* what;
  const char* min_default;
  const char* samples_default;
  bool positive;  ///< > 0; else any finite number
};

TimeAxisFlags AddMonitorTimeOption(CLI::App* sub, const MonitorTimeOption& t, double* min,
                                   double* samples) {
  const std::string name = std::string("--") + t.name;
  TimeAxisFlags f;
  f.min = sub->add_option(name + "-min", *min,
                          std::string(t.what) + " [min] (default " + t.min_default + ")")
              ->check(t.positive ? PositiveNumber("min") : FiniteNumber("min"));
  f.samples =
      sub->add_option(name + "-samples", *samples,
                      std::string(t.what) + " [samples], for runs without recorded time (default " +
                          t.samples_default + ")")
          ->check(t.positive ? PositiveNumber() : FiniteNumber());
  f.old = AddDeprecatedAlias(sub, f.min, name);
  return f;
}

void AddMonitorOptions(CLI::App* sub, MonitorArgs* a) {
  drift::MonitorOptions& o = a->o;
  sub->add_option("--model", a->model, "drift model file (whirl drift fit; kind mlr or dynamic)")
      ->required()
      ->check(CLI::ExistingFile);
  auto* run = sub->add_option("--run", a->run,
                              "run file with the model's error column (the check-bar values)")
                  ->check(CLI::ExistingFile);
  auto* day = sub->add_option("--day", a->days,
                              "a production week: day files in order (repeat); each rule carries "
                              "its updated coefficients from day to day")
                  ->check(CLI::ExistingFile);
  run->excludes(day);
  a->check_flags =
      AddMonitorTimeOption(sub,
                           {"check-every", "interval between check-bar checks",
                            "120: 3-4 checks in an 8-h shift; at most 100,000 checks", "120", true},
                           &a->check_every_min, &a->check_every_samples);
  sub->add_option("--threshold-um", o.threshold_um,
                  "validity threshold on |measured - predicted| [um] (default 0: use "
                  "--threshold-sigma)")
      ->check(NumberIn(0.0, 1e5));
  sub->add_option("--threshold-sigma", o.threshold_sigma,
                  "threshold as a multiple of sqrt(s^2 + noise^2), s the model's training residual "
                  "std [um] (default 3)")
      ->check(NumberIn(0.01, 100.0));
  sub->add_option(
         "--refit-samples", o.refit_samples,
         "m: further measurements after an invalid check (0..100, default 0: update from the "
         "check alone; 3 recommended with check-bar noise >= 0.5 um)")
      ->check(NumberIn(0, drift::kMaxRefitSamples));
  a->refit_flags = AddMonitorTimeOption(
      sub, {"refit-every", "interval between the refit measurements", "5", "5", true},
      &a->refit_every_min, &a->refit_every_samples);
  sub->add_option("--stop-min", o.stop_min_per_measurement,
                  "machine stop per check-bar measurement [min] (default 1)")
      ->check(NumberIn(0.0, 1440.0));
  sub->add_option("--update", a->updates,
                  "update rules replayed beside the static model: bayes (recursive least squares, "
                  "the training fit as prior; the recommended rule: its change is bounded), "
                  "patent (least-squares refit on the new measurements, rank-aware: only the "
                  "directions they identify change), offset (intercept only); default all three")
      ->delimiter(',')
      ->check(CLI::IsMember({"patent", "bayes", "offset"}));
  sub->add_option("--prior-scale", o.prior_scale,
                  "bayes: prior covariance = this x the training fit's Cov(b) (default 1), plus "
                  "the drift covariance estimated from the run's checks")
      ->check(NumberIn(1e-6, 1e12));
  sub->add_flag("--no-drift-estimate", a->no_drift_estimate,
                "bayes: no drift covariance (the prior is --prior-scale x Cov(b) alone; the "
                "default before the drift estimate was --prior-scale 100 this way)");
  sub->add_option(
         "--noise-um", o.noise_um,
         "std of the check-bar measurement noise added to the logged error [um] (default 0)")
      ->check(NumberIn(0.0, 1000.0));
  AddSeedOption(sub, &o.seed, "seed of the measurement noise (default 1)");
  a->start_flags = AddMonitorTimeOption(
      sub,
      {"start", "start of the monitoring (no check before it, scores from it)", "0", "0", false},
      &a->start_min, &a->start_samples);
  sub->add_option("--score-rows", a->score_rows,
                  "scored share of the run's rows FROM,TO (default 0,1; FL_THERMAL's test "
                  "window: 0.6,0.8)")
      ->check(NumberIn(0, 1))
      ->delimiter(',')
      ->expected(2);
  sub->add_option(
         "--reference", a->reference,
         "temperature reference of the rises: run-start (the run's first row, default, as in "
         "training) or model (the model's reference_C [degC])")
      ->check(CLI::IsMember({"run-start", "model"}));
  sub->add_option("--timeline", a->timeline,
                  "write the per-sample timeline CSV to this file (time, measured and each rule's "
                  "prediction and residual [um])");
  sub->add_option(
      "--events", a->events,
      "write every check, refit measurement and update with its reason to this CSV file");
  auto* out_dir = sub->add_option(
      "--out-dir", a->out_dir,
      std::string("write an HTML page with the plot, the timeline and events CSV into this "
                  "directory: ") +
          kOutputDirRule);
  AddDeprecatedAlias(sub, out_dir, "--report");
  sub->add_flag("--json", a->json, "machine output on stdout");
  AddProgressFlag(sub, &a->progress);
}

// The intervals from the flags named by their unit (ChooseTimeAxis: a *-min flag on a run
// without recorded time, or *-samples on one with time, is refused naming the flag).
void ApplyIntervals(MonitorArgs& a, bool time_from_index) {
  const struct {
    const TimeAxisFlags* flags;
    double min, samples;
    double* target;
  } intervals[] = {{&a.check_flags, a.check_every_min, a.check_every_samples, &a.o.check_every},
                   {&a.refit_flags, a.refit_every_min, a.refit_every_samples, &a.o.refit_every},
                   {&a.start_flags, a.start_min, a.start_samples, &a.o.start}};
  for (const auto& i : intervals) switch (ChooseTimeAxis(*i.flags, time_from_index)) {
      case TimeAxisValue::kMin:
        *i.target = i.min;
        break;
      case TimeAxisValue::kSamples:
        *i.target = i.samples;
        break;
      case TimeAxisValue::kNone:
        break;
    }
}

// Where a streamed replay's per-sample rows go: the --timeline file and the report's
// timeline.csv (inside its output directory's staging folder), written as the rows come.
struct TimelineFiles {
  std::unique_ptr<OutputDir> dir;  // --out-dir, opened before the replay
  std::unique_ptr<StreamedFile> flag, report;

  TimelineFiles(const std::string& timeline, const std::string& out_dir,
                const std::string& report_name = "timeline.csv") {
    if (!out_dir.empty()) {
      dir = std::make_unique<OutputDir>(out_dir, "--out-dir");
      report = std::make_unique<StreamedFile>(dir->Staging() / report_name);
    }
    if (!timeline.empty()) flag = std::make_unique<StreamedFile>(timeline);
  }
  std::vector<StreamedFile*> Files() const {
    std::vector<StreamedFile*> f;
    if (flag) f.push_back(flag.get());
    if (report) f.push_back(report.get());
    return f;
  }
};

// The --timeline and --events files and the report: all or none (the report with the files).
void CommitOutputs(const MonitorArgs& a, TimelineFiles& t, const std::string& events,
                   const std::function<drift::MonitorReportResult(
                       OutputDir&, const drift::AlsoWrite&, const std::vector<ReadyFile>&)>& report) {
  drift::AlsoWrite files;
  std::vector<ReadyFile> ready;
  if (t.flag) ready.push_back({a.timeline, t.flag->Finish()});
  if (!a.events.empty()) files.emplace_back(a.events, events);
  if (t.dir) {
    const auto rep = report(*t.dir, files, ready);
    for (const auto& w : rep.warnings) Warn(w);
    std::fprintf(stderr, "report: %s\n", rep.index_html.string().c_str());
  } else {
    WriteFilesAtomic(files, ready);  // all or none
  }
}

void RunWeek(MonitorArgs& a, const drift::DriftModel& m) {
  drift::CheckMonitorDays(a.days.size());  // before reading thousands of files
  std::vector<std::filesystem::path> days(a.days.begin(), a.days.end());
  const bool time_from_index = drift::ScanRun(days.front()).time_from_index;
  ApplyIntervals(a, time_from_index);
  std::fprintf(stderr, "replaying %zu days...\n", days.size());
  std::string command = "whirl drift monitor --model " + a.model;
  for (const auto& d : a.days) command += " --day " + d;
  const std::vector<std::string> prov{command};
  // The week's timeline (a day column first) to --timeline and the report; each day's own
  // timeline to the report; every day's plot rows kept (M4).
  TimelineFiles week(a.timeline, a.out_dir, "week_timeline.csv");
  std::vector<std::string> week_comments{"monitor timeline of a week, day by day"};
  week_comments.insert(week_comments.end(), prov.begin(), prov.end());
  for (std::size_t d = 0; d < days.size(); ++d)
    week_comments.push_back("day " + std::to_string(d + 1) + ": " + days[d].stem().string());
  std::vector<std::unique_ptr<StreamedFile>> day_files;
  std::vector<std::unique_ptr<drift::TimelineSink>> day_sinks;
  std::unique_ptr<drift::TimelineSink> week_sink;
  bool header = true;
  RowProgress progress(a.progress, a.json);
  const auto sink = [&](std::size_t d, const drift::MonitorSample& s) {
    if (s.index == 0) {
      if (week_sink) week_sink->Finish(nullptr);
      week_sink = std::make_unique<drift::TimelineSink>(a.o, time_from_index, week_comments,
                                                        week.Files(), static_cast<int>(d + 1), header);
      header = false;
      std::vector<StreamedFile*> own;
      if (week.dir) {
        day_files.push_back(std::make_unique<StreamedFile>(
            week.dir->Staging() / ("day" + std::to_string(d + 1) + "_timeline.csv")));
        own.push_back(day_files.back().get());
      }
      std::vector<std::string> c{"monitor timeline of " + days[d].stem().string()};
      c.insert(c.end(), prov.begin(), prov.end());
      day_sinks.push_back(std::make_unique<drift::TimelineSink>(a.o, time_from_index, c, own));
    }
    week_sink->Add(s);
    day_sinks.back()->Add(s);
  };
  drift::WeekResult w = drift::MonitorWeekFiles(m, days, a.o, sink, progress.Callback());
  progress.Finish();
  if (week_sink) week_sink->Finish(nullptr);
  for (std::size_t d = 0; d < w.days.size() && d < day_sinks.size(); ++d)
    day_sinks[d]->Finish(&w.days[d]);
  for (const auto& d : w.days)
    for (const auto& warning : d.warnings) Warn(warning);
  CommitOutputs(a, week, drift::WeekEventsCsv(w, prov),
                [&](OutputDir& dir, const drift::AlsoWrite& also, const std::vector<ReadyFile>& ready) {
                  std::vector<std::filesystem::path> day_ready;
                  for (auto& f : day_files) day_ready.push_back(f->Finish());
                  return drift::WriteWeekReport(dir, w, a.o, prov, "gnuplot", also, ready,
                                                day_ready, week.report->Finish());
                });
  if (a.json)
    PrintJson(drift::WeekJson(w, a.o));
  else
    std::fputs(drift::FormatWeek(w, a.o).c_str(), stdout);
}

void RunMonitor(MonitorArgs& a) {
  if (a.run.empty() && a.days.empty()) throw InputError("give --run FILE or --day FILE ...");
  std::vector<FlagPath> inputs{{"--model", a.model}, {"--run", a.run}};
  for (const auto& d : a.days) inputs.push_back({"--day", d});
  CheckOutputs(inputs, {{"--timeline", a.timeline}, {"--events", a.events}},
               {{"--out-dir", a.out_dir}});
  a.o.reference = drift::ParseReferenceMode(a.reference);
  a.o.score_from = a.score_rows.at(0);
  a.o.score_to = a.score_rows.at(1);
  a.o.estimate_drift = !a.no_drift_estimate;
  a.o.rules.clear();
  for (const auto& u : a.updates) a.o.rules.push_back(drift::ParseUpdateRule(u));
  const drift::DriftModel m = drift::ReadDriftModel(a.model);
  if (!a.days.empty()) return RunWeek(a, m);
  const drift::RunScan scan = drift::ScanRun(a.run);
  ApplyIntervals(a, scan.time_from_index);
  const std::string name = std::filesystem::path(a.run).stem().string();
  std::fprintf(stderr, "replaying checks on %s (%lld samples)...\n", name.c_str(), scan.rows);
  const std::vector<std::string> prov{"whirl drift monitor --model " + a.model + " --run " + a.run};
  // The run is streamed: the timeline rows go to their files as they come (fixed memory).
  TimelineFiles t(a.timeline, a.out_dir);
  std::vector<std::string> comments{"monitor timeline of " + name};
  comments.insert(comments.end(), prov.begin(), prov.end());
  drift::TimelineSink timeline(a.o, scan.time_from_index, comments, t.Files());
  RowProgress progress(a.progress, a.json);
  drift::MonitorResult r = drift::MonitorFile(
      m, a.run, a.o, {}, nullptr, [&](const drift::MonitorSample& s) { timeline.Add(s); },
      progress.Callback());
  progress.Finish();
  timeline.Finish(&r);
  CommitOutputs(a, t, drift::MonitorEventsCsv(r, prov),
                [&](OutputDir& dir, const drift::AlsoWrite& also, const std::vector<ReadyFile>& ready) {
                  return drift::WriteMonitorReport(dir, r, a.o, prov, "gnuplot", also, ready,
                                                   t.report->Finish());
                });
  if (a.json)
    PrintJson(drift::MonitorJson(r, a.o));
  else
    std::fputs(drift::FormatMonitor(r, a.o).c_str(), stdout);
}

}  // namespace

void RegisterDriftMonitor(CLI::App* drift_app) {
  auto a = std::make_shared<MonitorArgs>();
  auto* sub = drift_app->add_subcommand(
      "monitor",
      "Replay on a logged run the on-line model check of Liu et al.'s patent \"Temperature\n"
      "compensation method, system and medium for CNC machine tools\": temperatures every\n"
      "sample, the thermal error known only at check-bar measurements (every --check-every-min,\n"
      "each stopping the machine --stop-min [min]); a check with |measured - predicted| above\n"
      "the threshold marks the model invalid, --refit-samples more measurements follow and the\n"
      "coefficients are updated (patent: least squares on them; bayes: recursive least squares\n"
      "from the training posterior; offset: intercept only). Prints MAE, RMSE, max [um] for no\n"
      "compensation, the static model and each rule, with checks, recalibrations and stop time\n"
      "[min, % of time]. With --day ...: a production week, each rule carrying its coefficients\n"
      "from day to day, beside the \"previous run\" baseline (drift fit at its defaults redone\n"
      "on the previous day, as in drift report) and a time-only warm-up fitted on the previous day;\n"
      "--timeline and --events then hold every day (a day column first) and --out-dir a page\n"
      "with the week and each day.");
  AddMonitorOptions(sub, a.get());
  sub->callback([a] { RunMonitor(*a); });
}

}  // namespace whirl::cli
