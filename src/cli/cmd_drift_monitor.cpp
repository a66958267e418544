// whirl drift monitor: replay of the on-line model check with a check bar and the recalibration
// rules (Liu et al.'s check-bar patent) on a logged run (src/drift/monitor.h).
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "drift/monitor_report.h"

namespace whirl::cli {

namespace {

struct MonitorArgs {
  std::string model, run, reference = "run-start", timeline, events, report;
  std::vector<std::string> updates{"patent", "bayes", "offset"};
  std::vector<double> score_rows{0.0, 1.0};
  drift::MonitorOptions o;
  bool json = false;
};

void AddMonitorOptions(CLI::App* sub, MonitorArgs* a) {
  drift::MonitorOptions& o = a->o;
  sub->add_option("--model", a->model, "drift model file (whirl drift fit; mlr or dynamic)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--run", a->run, "run file with the model's error column (the check-bar values)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option(
         "--check-every", o.check_every,
         "interval between checks [min; samples if the run has no time] (default 60; at most "
         "100,000 checks per run)")
      ->check(PositiveNumber());
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
         "m: further measurements after an invalid check (0..100, default 3; 0: update from the "
         "check alone)")
      ->check(NumberIn(0, drift::kMaxRefitSamples));
  sub->add_option("--refit-every", o.refit_every,
                  "interval between the refit measurements [min; samples] (default 5)")
      ->check(PositiveNumber());
  sub->add_option("--stop-min", o.stop_min_per_measurement,
                  "machine stop per check-bar measurement [min] (default 1)")
      ->check(NumberIn(0.0, 1440.0));
  sub->add_option("--update", a->updates,
                  "update rules replayed beside the static model: patent (least-squares refit on "
                  "the new measurements), bayes (recursive least squares, the training fit as "
                  "prior), offset (intercept only); default all three")
      ->delimiter(',')
      ->check(CLI::IsMember({"patent", "bayes", "offset"}));
  sub->add_option("--prior-scale", o.prior_scale,
                  "bayes: prior covariance = this x the training fit's Cov(b) (default 1)")
      ->check(NumberIn(1e-6, 1e12));
  sub->add_option(
         "--noise-um", o.noise_um,
         "std of the check-bar measurement noise added to the logged error [um] (default 0)")
      ->check(NumberIn(0.0, 1000.0));
  AddSeedOption(sub, &o.seed, "seed of the measurement noise (default 1)");
  sub->add_option("--start", o.start,
                  "monitoring starts here [min; samples]: no check before, scores from here "
                  "(default 0)")
      ->check(FiniteNumber());
  sub->add_option("--score-rows", a->score_rows,
                  "scored share of the run's rows FROM,TO (default 0,1; FL_THERMAL's test "
                  "window: 0.6,0.8)")
      ->check(NumberIn(0, 1))
      ->delimiter(',')
      ->expected(2);
  sub->add_option("--reference", a->reference,
                  "temperature reference: run-start (default, as training) or model")
      ->check(CLI::IsMember({"run-start", "model"}));
  sub->add_option("--timeline", a->timeline,
                  "write the per-sample timeline CSV (time, measured and each rule's prediction "
                  "and residual [um])");
  sub->add_option("--events", a->events,
                  "write every check, refit measurement and update with its reason (CSV)");
  sub->add_option(
      "--report", a->report,
      std::string("write an HTML page with the plot into this directory: ") + kOutputDirRule);
  sub->add_flag("--json", a->json, "machine output on stdout");
}

void RunMonitor(MonitorArgs& a) {
  CheckOutputs({{"--model", a.model}, {"--run", a.run}},
               {{"--timeline", a.timeline}, {"--events", a.events}}, {{"--report", a.report}});
  a.o.reference = drift::ParseReferenceMode(a.reference);
  a.o.score_from = a.score_rows.at(0);
  a.o.score_to = a.score_rows.at(1);
  a.o.rules.clear();
  for (const auto& u : a.updates) a.o.rules.push_back(drift::ParseUpdateRule(u));
  const drift::DriftModel m = drift::ReadDriftModel(a.model);
  const drift::Run run = drift::ReadRun(a.run, drift::RunState::kUnknown);
  std::fprintf(stderr, "replaying checks on %s (%d samples)...\n", run.name.c_str(), run.samples());
  const drift::MonitorResult r = drift::MonitorRun(m, run, a.o);
  const std::vector<std::string> prov{"whirl drift monitor --model " + a.model + " --run " + a.run};
  const std::string timeline = drift::MonitorTimelineCsv(r, prov);
  const std::string events = drift::MonitorEventsCsv(r, prov);
  std::vector<std::pair<std::filesystem::path, std::string>> files;
  if (!a.timeline.empty()) files.emplace_back(a.timeline, timeline);
  if (!a.events.empty()) files.emplace_back(a.events, events);
  if (!a.report.empty()) {  // the report with the files: all or none
    const auto rep = drift::WriteMonitorReport(a.report, r, a.o, prov, "gnuplot", files);
    for (const auto& w : rep.warnings) Warn(w);
    std::fprintf(stderr, "report: %s\n", rep.index_html.string().c_str());
  } else {
    WriteFilesAtomic(files);  // both or neither
  }
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
      "Replay the patent's on-line check on a logged run: temperatures every sample, the thermal\n"
      "error known only at check-bar measurements (every --check-every, each stopping the\n"
      "machine --stop-min [min]); a check with |measured - predicted| above the threshold marks\n"
      "the model invalid, --refit-samples more measurements follow and the coefficients are\n"
      "updated (patent: least squares on them; bayes: recursive least squares from the training\n"
      "posterior; offset: intercept only). Prints MAE, RMSE, max [um] for no compensation, the\n"
      "static model and each rule, with checks, recalibrations and stop time [min, % of time].");
  AddMonitorOptions(sub, a.get());
  sub->callback([a] { RunMonitor(*a); });
}

}  // namespace whirl::cli
