// whirl drift: machine thermal drift from temperature sensors (Miao et al.): sensitive points,
// drift models, prediction, cross-run and hold-out evaluation, report (src/product/drift/).
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/common.h"
#include "cli/drift_args.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "drift/documents.h"
#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/report.h"
#include "drift/run_file.h"
#include "drift/stream.h"

namespace whirl::cli {
namespace {

using drift::RunState;

const char* kRunFilesHelp =
    "Run files: CSV, header row; time_s [s] or time_min [min] (empty/nan cells: the sample\n"
    "index is used and said so); temperatures <name>_C [degC]; errors <name>_um [um]; other\n"
    "columns (e.g. spindle_rpm) are optional inputs. At most 2,000,000 rows, 512 columns.\n"
    "UTF-8 text (a leading byte-order mark is skipped); decimal numbers only; names and cells\n"
    "may be in double quotes (RFC 4180, as a spreadsheet's \"quote all text cells\" export).\n";

const std::string kDeadSensorsHelp =
    "A sensor whose reading never moves (stuck, disconnected) or moves exactly as another (the\n"
    "same sensor twice) is left out with a warning naming it; runs with no moving sensor are an\n"
    "error.\n";

struct RunInputs {
  std::vector<std::string> runs, idle, cutting;
};

void AddRunOptions(CLI::App* sub, RunInputs* r, bool required = true) {
  auto* a =
      sub->add_option("--run", r->runs, "run file(s) of unstated state")->check(CLI::ExistingFile);
  auto* b = sub->add_option("--idle", r->idle, "run file(s) recorded in idle running")
                ->check(CLI::ExistingFile);
  auto* c = sub->add_option("--cutting", r->cutting, "run file(s) recorded while cutting")
                ->check(CLI::ExistingFile);
  if (required) {
    a->group("Runs (at least one)");
    b->group("Runs (at least one)");
    c->group("Runs (at least one)");
  }
}

// The run files as inputs for CheckOutputs; `prefix` "train-" for drift report's --train-*.
std::vector<FlagPath> InputPaths(const RunInputs& in, const std::string& prefix = "") {
  std::vector<FlagPath> paths;
  for (const auto& [flag, files] :
       {std::pair{"--run", &in.runs}, {"--idle", &in.idle}, {"--cutting", &in.cutting}})
    for (const auto& f : *files) paths.push_back({"--" + prefix + (flag + 2), f});
  return paths;
}

// The run files with their states, in LoadRuns' order (idle, cutting, unstated).
std::vector<drift::RunFile> RunFiles(const RunInputs& in) {
  std::vector<drift::RunFile> files;
  for (const auto& p : in.idle) files.push_back({p, RunState::kIdle});
  for (const auto& p : in.cutting) files.push_back({p, RunState::kCutting});
  for (const auto& p : in.runs) files.push_back({p, RunState::kUnknown});
  if (files.empty()) throw InputError("give at least one run file (--run, --idle or --cutting)");
  return files;
}

std::vector<drift::Run> LoadRuns(const RunInputs& in) {
  std::vector<drift::Run> runs;
  for (const auto& p : in.idle) runs.push_back(drift::ReadRun(p, RunState::kIdle));
  for (const auto& p : in.cutting) runs.push_back(drift::ReadRun(p, RunState::kCutting));
  for (const auto& p : in.runs) runs.push_back(drift::ReadRun(p, RunState::kUnknown));
  if (runs.empty()) throw InputError("give at least one run file (--run, --idle or --cutting)");
  for (const drift::Run& r : runs)
    if (r.time_from_index)
      Warn(r.source + ": no complete time column: the sample index is used as time");
  return runs;
}

struct ModelArgs {
  std::string kind = "mlr";
  std::vector<std::string> sensors, inputs;
  std::vector<double> lags_min, lags_samples;  // --lag-grid-min, --lag-grid-samples
  TimeAxisFlags lag_flags;
  int max_lags = 2, folds = 5, hidden = 3, restarts = 3, epochs = 1000;
  bool shuffle_cv = false;
  std::uint64_t seed = 1;
  int threads = 0;
  std::string error_zero = "run-start", candidates = "auto";
  double gauge_level_um = std::numeric_limits<double>::quiet_NaN();
};

// The dynamic model's options (lagged copies of the rises), shared by every command that fits it.
void AddDynamicOptions(CLI::App* sub, ModelArgs* m) {
  sub->add_option("--inputs", m->inputs, "other columns used as inputs as logged, e.g. spindle_rpm")
      ->delimiter(',');
  m->lag_flags.min = sub->add_option("--lag-grid-min", m->lags_min,
                                     "dynamic: candidate lag time constants [min], comma-separated "
                                     "(default 5,10,20,40,80,160,320)")
                         ->check(PositiveNumber("min"))
                         ->delimiter(',');
  m->lag_flags.samples =
      sub->add_option("--lag-grid-samples", m->lags_samples,
                      "dynamic: the same in samples, for runs without recorded time (default "
                      "5,10,20,40,80,160,320 samples)")
          ->check(PositiveNumber())
          ->delimiter(',');
  m->lag_flags.old = AddDeprecatedAlias(sub, m->lag_flags.min, "--lag-grid");
  sub->add_option("--max-lags", m->max_lags,
                  "dynamic: at most this many time constants (1..4, default 2)")
      ->check(NumberIn(1, 4));
  sub->add_option("--folds", m->folds,
                  "cross-validation blocks of a single training run, for the lag search and the "
                  "choice among --candidates (2..20, default 5)")
      ->check(NumberIn(2, 20));
  sub->add_flag("--leave-block-out", m->shuffle_cv,
                "leave-one-block-out instead of forward-chaining blocks (lag search and "
                "candidates)");
}

// --error-zero (old spelling --errors-from-start: run-start), --gauge-level-um (every command
// that fits or evaluates).
void AddZeroOptions(CLI::App* sub, ModelArgs* m) {
  auto* zero =
      sub->add_option(
             "--error-zero", m->error_zero,
             "zero of the errors for the model, 'none' and every baseline alike: run-start "
             "(e - e at the run's first row, default; a gauge level cancels) or fixed "
             "(e - --gauge-level-um, for a machine never re-referenced); stored in the model")
          ->check(CLI::IsMember({"run-start", "fixed"}));
  AddDeprecatedAlias(sub, zero, "--errors-from-start", "run-start");
  sub->add_option("--gauge-level-um", m->gauge_level_um,
                  "fixed zero: the gauge level [um] (default: the first row of the first training "
                  "run)")
      ->check(FiniteNumber("um"));
}

// --candidates (every command that fits a model the way drift fit does).
void AddCandidatesOption(CLI::App* sub, ModelArgs* m, const std::string& what) {
  sub->add_option(
         "--candidates", m->candidates,
         what + ": the model families scored by validation on the training runs (the whole fit "
                "redone in every fold: leave one run out, or forward-chaining blocks of one run): "
                "auto (default: sensors, time1, time2, and sensors+time with >= 3 runs; the "
                "fewest parameters within 5 % of the lowest validation RMSE, and a time model "
                "replaces the sensors only 20 % lower and lower in 3 of 4 folds; with --model "
                "mlr and the selection, a sensor model chosen is blended 75 % / 25 % with the "
                "one chosen by the same rule with lagged sensors (--model dynamic)), sensors, time "
                "(first-order warm-up in time since the run start, 1 or 2 terms, each time "
                "constant at most the longest training run, gains of one sign), time1, time2 or "
                "sensors+time")
      ->check(CLI::IsMember({"auto", "sensors", "time", "time1", "time2", "sensors+time"}));
}

// --model, the sensors, the dynamic and the network model's options, --threads.
void AddModelOptions(CLI::App* sub, ModelArgs* m) {
  sub->add_option("--model", m->kind,
                  "mlr (Miao et al.'s regression on the rises), dynamic (rises plus first-order "
                  "lagged copies, time constants by cross-validation) or network (Bayesian-"
                  "regularized k-h-1); default mlr")
      ->check(CLI::IsMember({"mlr", "dynamic", "network"}));
  sub->add_option("--sensors", m->sensors,
                  "use these _C columns (comma-separated) instead of Miao et al.'s selection")
      ->delimiter(',');
  AddDynamicOptions(sub, m);
  sub->add_option("--hidden", m->hidden, "network: hidden neurons h (1..20, default 3)")
      ->check(NumberIn(1, 20));
  sub->add_option("--restarts", m->restarts,
                  "network: trainbr restarts, the highest evidence kept (1..50, default 3)")
      ->check(NumberIn(1, 50));
  sub->add_option("--epochs", m->epochs, "network: trainbr epochs (1..10000, default 1000)")
      ->check(NumberIn(1, 10000));
  AddSeedOption(sub, &m->seed, "network: initialization seed (default 1)");
  sub->add_option("--threads", m->threads,
                  "threads for cross-validation and restarts (0: all cores, default)")
      ->check(NumberIn(0, 256));
  AddZeroOptions(sub, m);
}

// The fit's options for runs with (`time_from_index` false) or without recorded time (the unit
// of the lag grid).
drift::FitOptions ToFit(const ModelArgs& m, const SelectionArgs& s, bool time_from_index) {
  drift::FitOptions o;
  o.kind = drift::ParseModelKind(m.kind);
  o.sensors = m.sensors;
  o.extra_inputs = m.inputs;
  switch (ChooseTimeAxis(m.lag_flags, time_from_index)) {
    case TimeAxisValue::kMin:
      o.tau_grid = m.lags_min;
      break;
    case TimeAxisValue::kSamples:
      o.tau_grid = m.lags_samples;
      break;
    case TimeAxisValue::kNone:
      break;
  }
  o.max_lags = m.max_lags;
  o.folds = m.folds;
  o.forward_cv = !m.shuffle_cv;
  o.hidden = m.hidden;
  o.restarts = m.restarts;
  o.train.epochs = m.epochs;
  o.seed = m.seed;
  o.threads = m.threads;
  o.selection = ToSelection(s);
  o.zero.zero = drift::ParseErrorZero(m.error_zero);
  o.zero.gauge_level_um = m.gauge_level_um;
  if (o.zero.zero != drift::ErrorZero::kFixed && !std::isnan(m.gauge_level_um))
    throw InputError("--gauge-level-um " + MessageNumber(m.gauge_level_um) +
                     ": only with --error-zero fixed");
  o.candidates = drift::ParseCandidates(m.candidates);
  return o;
}

// FitFiles on the run files (streamed: any length), with LoadRuns' warning for runs without time
// (`warn` false: the caller warns for the same runs itself, as drift report does).
drift::FitReport FitRunFiles(const RunInputs& in, const std::string& error, const ModelArgs& m,
                             const SelectionArgs& sel, RowProgress* progress, bool warn = true) {
  const std::vector<drift::RunFile> files = RunFiles(in);
  // The time axis of the options (the lag grid's unit) is the runs': ask the first file.
  const bool time_from_index = drift::ScanRun(files.front().path).time_from_index;
  drift::FitReport rep = drift::FitFiles(files, error, ToFit(m, sel, time_from_index),
                                         progress ? progress->Callback() : drift::StreamProgress());
  if (progress) progress->Finish();
  if (warn && rep.model.time_unit == "sample")
    for (const auto& f : files)
      Warn(f.path.string() + ": no complete time column: the sample index is used as time");
  return rep;
}

void RegisterSelect(CLI::App* drift_app) {
  struct Opts {
    RunInputs runs;
    SelectionArgs sel;
    std::string error;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sub = drift_app->add_subcommand(
      "select",
      std::string(
          "Temperature-sensitive points as Miao et al.: similarity |Pearson r| of the rises,\n"
          "fuzzy equivalence by max-min squaring, lambda-cuts, F test for the class count,\n"
          "Deng's grey grade (rho 0.5) against the error to pick one sensor per class.\n"
          "Prints the lambda levels with partitions and F values, the grades, the choice.\n" +
          kDeadSensorsHelp) +
          kRunFilesHelp);
  AddRunOptions(sub, &o->runs);
  AddSelectionOptions(sub, &o->sel);
  sub->add_option("--error", o->error, "error column (<name>_um) the sensors must explain")
      ->required();
  sub->add_flag("--json", o->json, "machine output on stdout");
  sub->callback([o] {
    const auto runs = LoadRuns(o->runs);
    drift::FitOptions fit;  // --classes cv scores each count with the fit's cross-validation
    fit.selection = ToSelection(o->sel);
    const drift::Selection s = drift::SelectSensorsForFit(runs, o->error, fit);
    for (const auto& w : s.left_out) Warn(w);
    if (o->json)
      PrintJson({{"schema", "whirl.drift_select"},
                 {"schema_version", 1},
                 {"error_column", o->error},
                 {"selection", drift::SelectionJson(s)}});
    else
      std::fputs(drift::FormatSelection(s).c_str(), stdout);
  });
}

void RegisterFitModel(CLI::App* drift_app) {
  struct Opts {
    RunInputs runs;
    SelectionArgs sel;
    ModelArgs model;
    std::string error, out;
    bool json = false, progress = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sub = drift_app->add_subcommand(
      "fit",
      std::string("Fit a drift model of one error channel [um] on the training runs and write it\n"
                  "as a versioned JSON file (sensors, reference temperatures [degC], coefficients\n"
                  "[um/K for rises; um per the input's unit for other inputs; um for elapsed-time\n"
                  "terms] with standard errors, VIF, residual std [um], lag time constants [min;\n"
                  "samples on runs without time], error zero, training runs, state and ranges).\n"
                  "By default the sensor model competes with sensor-free time-only warm-up\n"
                  "models (--candidates); the table of candidates and the choice are printed.\n" +
                  kDeadSensorsHelp) +
          kRunFilesHelp);
  AddRunOptions(sub, &o->runs);
  AddSelectionOptions(sub, &o->sel);
  AddModelOptions(sub, &o->model);
  AddCandidatesOption(sub, &o->model, "the model written");
  sub->add_option("--error", o->error, "error column to model (<name>_um)")->required();
  sub->add_option("--out", o->out, "model file to write (JSON)")->required();
  sub->add_flag("--json", o->json, "machine output on stdout");
  AddProgressFlag(sub, &o->progress);
  sub->callback([o] {
    CheckOutputs(InputPaths(o->runs), {{"--out", o->out}});
    std::fprintf(stderr, "fitting %s model of %s on %zu run(s)...\n", o->model.kind.c_str(),
                 o->error.c_str(), RunFiles(o->runs).size());
    RowProgress progress(o->progress, o->json);
    drift::FitReport rep = FitRunFiles(o->runs, o->error, o->model, o->sel, &progress);
    for (const auto& w : rep.warnings) Warn(w);
    rep.model.notes.push_back("whirl drift fit --model " + o->model.kind + " --error " + o->error);
    drift::WriteDriftModel(o->out, rep.model);
    if (o->json) {
      nlohmann::json j = {{"schema", "whirl.drift_fit"},
                          {"schema_version", 1},
                          {"model_file", o->out},
                          {"model", drift::ModelSummaryJson(rep.model)}};
      if (rep.selected) j["selection"] = drift::SelectionJson(rep.selection);
      if (!rep.candidates.empty()) j["candidates"] = drift::CandidatesJson(rep);
      if (!rep.train_report.empty()) j["trainbr"] = rep.train_report;
      PrintJson(j);
      return;
    }
    if (rep.selected) std::fputs(drift::FormatSelection(rep.selection).c_str(), stdout);
    std::fputs(drift::FormatCandidates(rep).c_str(), stdout);
    std::fputs(drift::FormatModel(rep.model).c_str(), stdout);
    if (!rep.train_report.empty()) std::printf("  %s\n", rep.train_report.c_str());
    std::printf("model written to %s\n", o->out.c_str());
  });
}

void RegisterPredictDrift(CLI::App* drift_app) {
  struct Opts {
    std::string model, run, out, reference = "run-start";
    bool json = false, progress = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sub = drift_app->add_subcommand(
      "predict",
      "Evaluate a drift model on a run sample by sample (as the control would) and write the\n"
      "compensation value per sample: CSV columns time_min [min], predicted_um, compensation_um\n"
      "(= -predicted) [um], std_um [um], and measured_um, residual_um [um] when the run has the\n"
      "model's error column. Warns when inputs leave the training range.\n" +
          std::string(kRunFilesHelp));
  sub->add_option("--model", o->model, "drift model file (whirl drift fit)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--run", o->run, "run file (format below)")->required()->check(CLI::ExistingFile);
  sub->add_option("--out", o->out, "write the per-sample prediction to this CSV file");
  sub->add_option("--reference", o->reference,
                  "temperature reference of the rises: run-start (the run's first row, default, "
                  "as in training) or model (the model's reference_C [degC])")
      ->check(CLI::IsMember({"run-start", "model"}));
  sub->add_flag("--json", o->json, "machine output on stdout");
  AddProgressFlag(sub, &o->progress);
  sub->callback([o] {
    CheckOutputs({{"--model", o->model}, {"--run", o->run}}, {{"--out", o->out}});
    const drift::DriftModel m = drift::ReadDriftModel(o->model);
    // The run is streamed: each sample goes to the CSV as it is predicted (fixed memory).
    std::unique_ptr<StreamedFile> out;
    std::string rows;
    const auto flush = [&] { out->Append(rows), rows.clear(); };
    const auto sink = [&](const drift::PredictedSample& p) {
      if (!out) return;
      if (p.index == 0)
        rows = drift::PredictionCsvHeader(
            m.time_unit == "sample", p.has_measured,
            {"whirl drift predict --model " + o->model + " --run " + o->run + " --reference " +
             o->reference});
      drift::AppendPredictionRow(p.time, p.predicted_um, p.std_um,
                                 p.has_measured ? &p.measured_um : nullptr, &rows);
      if (rows.size() >= (1u << 20)) flush();
    };
    if (!o->out.empty()) out = std::make_unique<StreamedFile>(o->out);
    RowProgress progress(o->progress, o->json);
    const drift::PredictionSummary p = drift::PredictFile(
        m, o->run, drift::ParseReferenceMode(o->reference), sink, progress.Callback());
    progress.Finish();
    for (const auto& w : p.warnings) Warn(w);
    if (out) {
      flush();
      out->Commit();
    }
    if (o->json) {
      PrintJson({{"schema", "whirl.drift_predict"},
                 {"schema_version", 1},
                 {"model", o->model},
                 {"out", o->out},
                 {"prediction", drift::PredictionJson(p)}});
      return;
    }
    std::printf("%s: %lld samples, predicted %s from %.3f to %.3f um\n", p.run.c_str(), p.samples,
                m.error_column.c_str(), p.predicted_min_um, p.predicted_max_um);
    if (p.has_measured) {
      const auto& r = p.residual;
      const auto& n = p.none;
      std::printf(
          "residual: MAE %.3f, RMSE %.3f, max %.3f um (no compensation: MAE %.3f, RMSE "
          "%.3f, max %.3f um)\n",
          r.mae_um, r.rmse_um, r.max_abs_um, n.mae_um, n.rmse_um, n.max_abs_um);
    }
    if (!o->out.empty()) std::printf("written to %s\n", o->out.c_str());
  });
}

void RegisterCrossval(CLI::App* drift_app) {
  struct Opts {
    RunInputs runs;
    SelectionArgs sel;
    ModelArgs model;
    std::string error;
    bool json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sub = drift_app->add_subcommand(
      "crossval",
      std::string("Cross-run evaluation as Miao et al.'s tables 6-8: a model built on each run\n"
                  "(own sensor selection) predicts every run; RMSE, std and max |error| [um] per\n"
                  "pair, "
                  "group means (idle on idle, idle on cutting, cutting on cutting, ...) beside no\n"
                  "compensation, MLR on all sensors and the sensor-free time-only warm-up model\n"
                  "of the training run, all on one error zero; each group names the strongest.\n") +
          kRunFilesHelp);
  AddRunOptions(sub, &o->runs);
  AddSelectionOptions(sub, &o->sel);
  AddModelOptions(sub, &o->model);
  AddCandidatesOption(sub, &o->model, "each run's model (the 'model' column)");
  sub->add_option("--error", o->error, "error column (<name>_um)")->required();
  sub->add_flag("--json", o->json, "machine output on stdout");
  sub->callback([o] {
    auto runs = LoadRuns(o->runs);
    std::fprintf(stderr, "cross-run evaluation of %zu runs...\n", runs.size());
    const auto r =
        drift::CrossRun(runs, o->error, ToFit(o->model, o->sel, runs.front().time_from_index));
    for (const auto& w : r.warnings) Warn(w);
    if (o->json)
      PrintJson(drift::CrossRunJson(r));
    else
      std::fputs(drift::FormatCrossRun(r).c_str(), stdout);
  });
}

void RegisterHoldout(CLI::App* drift_app) {
  struct Opts {
    std::string log;
    drift::HoldoutOptions h;
    ModelArgs model;
    SelectionArgs sel;
    std::vector<std::string> channels;
    std::string out_dir;
    bool no_network = false, json = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sub = drift_app->add_subcommand(
      "holdout",
      std::string(
          "Chronological hold-out on one long log (the split of the FL_THERMAL data set):\n"
          "train on the first --train share of the rows, test on the next --test share; the\n"
          "models run from the log's first row. Per channel: none, fit (drift fit as run by\n"
          "default: --candidates, kind mlr), time (sensor-free warm-up in time since the log's\n"
          "start), mlr_all (all sensors), mlr, dynamic and network on\n"
          "the selected sensors (at most --max-sensors), dynamic_extra with --inputs, all on one\n"
          "error zero. Test and train MAE, RMSE, max [um]; the strongest per channel.\n") +
          kRunFilesHelp);
  sub->add_option("--log", o->log, "the log (a run file)")->required()->check(CLI::ExistingFile);
  sub->add_option("--train", o->h.train_fraction, "training share of the rows (default 0.6)")
      ->check(NumberIn(0.01, 0.99));
  sub->add_option("--test", o->h.test_fraction, "test share after it (default 0.2)")
      ->check(NumberIn(0.01, 0.99));
  sub->add_option("--channels", o->channels,
                  "error columns, comma-separated (default: every _um column)")
      ->delimiter(',');
  AddSelectionOptions(sub, &o->sel);
  AddZeroOptions(sub, &o->model);
  AddCandidatesOption(sub, &o->model, "the 'fit' row (drift fit's own choice, kind mlr, no sensor cap)");
  sub->add_flag("--no-network", o->no_network, "skip the network model");
  AddDynamicOptions(sub, &o->model);  // --inputs: those of dynamic_extra
  sub->add_option("--epochs", o->model.epochs, "network: trainbr epochs (1..10000, default 1000)")
      ->check(NumberIn(1, 10000));
  auto* out_dir = sub->add_option("--out-dir", o->out_dir,
                                  std::string("also write an HTML report (index.html, plots, CSV) "
                                              "into this directory: ") +
                                      kOutputDirRule);
  AddDeprecatedAlias(sub, out_dir, "--report");
  sub->add_flag("--json", o->json, "machine output on stdout");
  sub->callback([o] {
    CheckOutputs({{"--log", o->log}}, {}, {{"--out-dir", o->out_dir}});
    const drift::Run log = drift::ReadRun(o->log, RunState::kUnknown);
    drift::HoldoutOptions h = o->h;
    h.channels = o->channels;
    h.network = !o->no_network;
    h.fit = ToFit(o->model, o->sel, log.time_from_index);
    h.max_sensors = o->sel.max_sensors;
    const auto r = drift::Holdout(
        log, h, [](const std::string& s) { std::fprintf(stderr, "fitting %s\n", s.c_str()); });
    for (const auto& w : r.warnings) Warn(w);
    if (!o->out_dir.empty()) {
      const auto rep =
          drift::WriteHoldoutReport(o->out_dir, log, r, {"whirl drift holdout --log " + o->log});
      for (const auto& w : rep.warnings) Warn(w);
      std::fprintf(stderr, "report: %s\n", rep.index_html.string().c_str());
    }
    if (o->json)
      PrintJson(drift::HoldoutJson(r));
    else
      std::fputs(drift::FormatHoldout(r).c_str(), stdout);
  });
}

void RegisterSplit(CLI::App* drift_app) {
  struct Opts {
    std::string log, column = "spindle_rpm", out_dir, state = "unknown";
    double threshold = 0;
    bool json = false, progress = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sub = drift_app->add_subcommand(
      "split",
      "Cut one long log into run files, a new run at every machine start: where --at (default\n"
      "spindle_rpm) rises from <= --threshold to above it. Writes <out-dir>/<log>_<k>.csv in the\n"
      "run-file format (time_min [min]); all or nothing.");
  sub->add_option("--log", o->log, "the log (a run file)")->required()->check(CLI::ExistingFile);
  sub->add_option("--at", o->column, "column whose rise starts a run (default spindle_rpm)");
  sub->add_option("--threshold", o->threshold, "start threshold in the column's unit (default 0)")
      ->check(FiniteNumber());
  sub->add_option("--out-dir", o->out_dir,
                  std::string("directory for the run files: ") + kOutputDirRule)
      ->required();
  sub->add_flag("--json", o->json, "machine output on stdout");
  AddProgressFlag(sub, &o->progress);
  sub->callback([o] {
    CheckOutputs({{"--log", o->log}}, {}, {{"--out-dir", o->out_dir}});
    RowProgress progress(o->progress, o->json);
    const std::string step = "splitting " + o->log;
    // Streamed: each run file is written as its rows arrive (fixed memory), all or nothing.
    const auto runs = drift::SplitLogFile(
        o->log, o->column, o->threshold, o->out_dir,
        {"whirl drift split --log " + o->log + " --at " + o->column}, "--out-dir",
        [&](long long rows, double fraction) { progress.Update(step, rows, fraction); });
    progress.Finish();
    nlohmann::json list = nlohmann::json::array();
    for (const auto& r : runs)
      list.push_back({{"file", r.file.string()},
                      {"samples", r.samples},
                      {"start_min", r.start_min},
                      {"end_min", r.end_min}});
    if (o->json) {
      PrintJson({{"schema", "whirl.drift_split"}, {"schema_version", 1}, {"runs", list}});
      return;
    }
    for (const auto& r : runs)
      std::printf("%s: %lld samples, %.1f to %.1f h\n", r.file.string().c_str(), r.samples,
                  r.start_min / 60, r.end_min / 60);
  });
}

void RegisterReport(CLI::App* drift_app) {
  struct Opts {
    RunInputs train, runs;
    SelectionArgs sel;
    ModelArgs model;
    std::string error, out_dir;
    bool json = false, progress = false;
  };
  auto o = std::make_shared<Opts>();
  auto* sub = drift_app->add_subcommand(
      "report",
      std::string(
          "HTML report for a process engineer: fit a model on the training runs (--train-*)\n"
          "and show, per run, measured and predicted error over time [um], the residuals,\n"
          "the similarity matrix and lambda levels of the selection, the chosen sensors and\n"
          "the coefficients. Plots by gnuplot (skipped with a warning if absent).\n") +
          kRunFilesHelp);
  sub->add_option("--train-run", o->train.runs, "training run file(s)")->check(CLI::ExistingFile);
  sub->add_option("--train-idle", o->train.idle, "training run file(s), idle")
      ->check(CLI::ExistingFile);
  sub->add_option("--train-cutting", o->train.cutting, "training run file(s), cutting")
      ->check(CLI::ExistingFile);
  AddRunOptions(sub, &o->runs, false);
  AddSelectionOptions(sub, &o->sel);
  AddModelOptions(sub, &o->model);
  AddCandidatesOption(sub, &o->model, "the model shown");
  sub->add_option("--error", o->error, "error column (<name>_um)")->required();
  auto* out_dir = sub->add_option("--out-dir", o->out_dir,
                                  std::string("write the report (index.html, plots, a prediction "
                                              "CSV per run) into this directory: ") +
                                      kOutputDirRule)
                      ->required();
  AddDeprecatedAlias(sub, out_dir, "--out");
  sub->add_flag("--json", o->json,
                "machine output on stdout: the model, the selection and each run's residual "
                "against no compensation [um]");
  AddProgressFlag(sub, &o->progress);
  sub->callback([o] {
    std::vector<FlagPath> inputs = InputPaths(o->train, "train-"), more = InputPaths(o->runs);
    inputs.insert(inputs.end(), more.begin(), more.end());
    CheckOutputs(inputs, {}, {{"--out-dir", o->out_dir}});
    const bool shown = !o->runs.runs.empty() || !o->runs.idle.empty() || !o->runs.cutting.empty();
    // The model as drift fit makes it (streamed; a thinned search on long training runs).
    RowProgress progress(o->progress, o->json);
    const drift::FitReport rep =
        FitRunFiles(o->train, o->error, o->model, o->sel, &progress, /*warn=*/shown);
    for (const auto& w : rep.warnings) Warn(w);
    // The runs shown are streamed too: each pass over a file is a block of rows at a time.
    const std::vector<drift::RunFile> runs = RunFiles(shown ? o->runs : o->train);
    const auto r = drift::WriteModelReport(o->out_dir, rep, runs,
                                           {"whirl drift report --error " + o->error}, "gnuplot",
                                           progress.Callback());
    progress.Finish();
    for (std::size_t i = 0; i < runs.size(); ++i)
      if (r.predictions[i].time_from_index)
        Warn(runs[i].path.string() + ": no complete time column: the sample index is used as time");
    for (const auto& w : r.warnings) Warn(w);
    if (!o->json) {
      std::printf("report written to %s\n", r.index_html.string().c_str());
      return;
    }
    nlohmann::json predictions = nlohmann::json::array(), files = nlohmann::json::array();
    for (const drift::PredictionSummary& p : r.predictions)
      predictions.push_back(drift::PredictionJson(p));
    for (const auto& f : r.files) files.push_back(f.string());
    nlohmann::json j = {{"schema", "whirl.drift_report"},
                        {"schema_version", 1},
                        {"index_html", r.index_html.string()},
                        {"files", files},
                        {"model", drift::ModelSummaryJson(rep.model)},
                        {"runs", predictions}};
    if (rep.selected) j["selection"] = drift::SelectionJson(rep.selection);
    if (!rep.candidates.empty()) j["candidates"] = drift::CandidatesJson(rep);
    j["baselines"] = drift::ReportBaselinesJson(r.baselines, r.baseline_notes);
    PrintJson(j);
  });
}

}  // namespace

void RegisterDriftMonitor(CLI::App* drift_app);  // cmd_drift_monitor.cpp
void RegisterDriftFitGrey(CLI::App* drift_app);  // cmd_drift_fit_grey.cpp
void RegisterDrift(CLI::App& app) {
  auto* sub = app.add_subcommand(
      "drift",
      "Machine thermal drift from temperature sensors (Miao et al.): select sensitive points, fit\n"
      "MLR / dynamic / network drift models, predict the compensation per sample, cross-run and\n"
      "hold-out evaluation, HTML report, the 840D program of the live compensation (nc) and the\n"
      "replay of an on-line check with a check bar (monitor).");
  sub->require_subcommand(1);
  RegisterSelect(sub);
  RegisterFitModel(sub);
  RegisterDriftFitGrey(sub);
  RegisterPredictDrift(sub);
  RegisterCrossval(sub);
  RegisterHoldout(sub);
  RegisterSplit(sub);
  RegisterReport(sub);
  RegisterDriftNc(sub);  // cmd_drift_nc.cpp
  RegisterDriftMonitor(sub);
}

}  // namespace whirl::cli
