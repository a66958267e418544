// whirl machine: the whirling machine's own thermal drift (src/machine/machine.h).
//   whirl machine sensors  --out DIR   virtual-sensor run files in the drift format
//   whirl machine evaluate             none / traditional / workpiece / machine / both / both_idle
//                                      (legacy world); --scenarios: the field world's table over
//                                      seeds (machine_eval/field_eval.h)
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "cli/common.h"
#include "cli/drift_args.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "core/process.h"
#include "core/random.h"
#include "drift/model.h"
#include "drift/run_file.h"
#include "interp/machine_profile.h"
#include "machine/machine.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"
#include "machine_eval/machine_eval.h"
#include "machine_eval/seeds.h"
#include "workpiece/model.h"
#include "sim/screw.h"

namespace whirl::cli {
namespace {

struct MachineCliOptions {
  std::string machine_path = ProjectPath("datasets/machines/whirling_thermal.json");
  std::uint64_t machine_seed = 1, seed = 1;
  // sensors
  std::string out;
  int idle = 2, cutting = 2;
  // evaluate
  std::string model_path = ProjectPath("models/default.json");
  std::string history = ProjectPath(kHistoryTable);
  std::string base_screw = ProjectPath("datasets/screws/reference_80x10x6000.json");
  std::string iso_table = ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv");
  int machines = 2, screws = 3, train_runs = 2, threads = 2;
  bool machine_off = false, markdown = false, json = false;
  SelectionArgs selection;
  std::string drift_model = "mlr";
  double monitor_every_min = 30;
  int seeds = 1;
  double travel_c_um = 0;
  std::string report;
  std::string profile = ProjectPath("datasets/machines/whirling_840d.json");
  // field scenarios
  std::string scenarios = "legacy";
  int test_days = 2, past_days = 5;
  double check_every_min = 10, probe_noise_um = 1.0, laser_every_min = 20, lead_sample_min = 5;
  bool no_setup_checks = false;
  std::vector<CLI::Option*> legacy_only, field_only;  ///< flags that apply to one world only
};

// A flag of one world given while no selected scenario is of that world: InputError naming it.
void CheckWorldFlags(const MachineCliOptions& o, bool any_legacy, bool any_field) {
  for (const auto* opt : o.legacy_only)
    if (opt->count() > 0 && !any_legacy)
      throw InputError(opt->get_name() + ": applies to the legacy world only; --scenarios " +
                       o.scenarios + " selects no legacy scenario");
  for (const auto* opt : o.field_only)
    if (opt->count() > 0 && !any_field)
      throw InputError(opt->get_name() + ": applies to the field scenarios only; --scenarios " +
                       o.scenarios + " selects only the legacy world");
}

machine_eval::FieldEvalOptions FieldOptions(const MachineCliOptions& o) {
  machine_eval::FieldEvalOptions f;
  f.machines = o.machines;
  f.seed = o.seed;
  f.threads = o.threads;
  f.calendar.test_days = o.test_days;
  f.calendar.past_days = o.past_days;
  f.protocol.check_every_min = o.check_every_min;
  f.protocol.probe_sigma_um = o.probe_noise_um;
  f.protocol.laser_every_min = o.laser_every_min;
  f.protocol.lead_sample_min = o.lead_sample_min;
  f.protocol.setup_checks = !o.no_setup_checks;
  return f;
}

machine::MachineConfig LoadMachine(const MachineCliOptions& o) {
  // Only the shipped default may be missing (a clone without datasets/): a named file must exist.
  const bool shipped = o.machine_path == ProjectPath("datasets/machines/whirling_thermal.json");
  machine::MachineConfig m = shipped && !std::filesystem::exists(o.machine_path)
                                 ? machine::DefaultMachine()
                                 : machine::ReadMachine(o.machine_path);
  if (o.machine_off) m.DisableAll();
  return m;
}

void RunSensors(const MachineCliOptions& o) {
  CheckOutputs({{"--machine-thermal", o.machine_path}}, {}, {{"--out-dir", o.out}});
  const machine::MachineConfig config = LoadMachine(o);
  std::vector<drift::Run> runs;
  for (auto state : {drift::RunState::kIdle, drift::RunState::kCutting})
    for (auto& r : machine_eval::TrainingRuns(
             config, o.machine_seed, state == drift::RunState::kIdle ? o.idle : o.cutting, state))
      runs.push_back(r);
  const std::vector<std::string> comments = {
      "simulated by: whirl machine sensors --machine-seed " + std::to_string(o.machine_seed) +
          " (src/machine/machine.h; idle 180 min, cutting 150 min)",
      "offset_um = head + bed drift (SD43900 part); zscrew_per_1000_um = Z screw growth over "
      "1000 mm (SD43910 part)"};
  const auto paths = drift::WriteRuns(o.out, runs, comments, "--out-dir");
  if (o.json) {
    nlohmann::json files = nlohmann::json::array();
    for (std::size_t k = 0; k < paths.size(); ++k)
      files.push_back({{"path", paths[k].string()}, {"state", drift::ToString(runs[k].state)}});
    PrintJson({{"schema", "whirl.machine_sensors"}, {"schema_version", 1}, {"files", files}});
    return;
  }
  for (std::size_t k = 0; k < paths.size(); ++k)
    std::printf("%s (%s, %d samples)\n", paths[k].string().c_str(),
                drift::ToString(runs[k].state).c_str(), runs[k].samples());
}

// --seeds N > 1: the evaluation over seeds S..S+N-1 (machine_eval/seeds.h).
void RunOverSeeds(const MachineCliOptions& o, const sim::Screw& base, const workpiece::WorkpieceModel& model,
                  const compare::ExperienceRule& rule, const compare::IsoToleranceTable& iso,
                  const machine_eval::MachineEvalOptions& eo) {
  Progress progress("machine evaluate",
                    static_cast<std::size_t>(o.seeds * o.machines * o.screws));
  machine_eval::SeedsEvaluation e = machine_eval::EvaluateOverSeeds(
      base, model, rule, iso, eo, o.seeds, [&](std::size_t d, std::size_t) { progress.Update(d); });
  progress.Finish();
  e.travel_c_um = o.travel_c_um;
  if (o.json)
    PrintJson(e);
  else
    std::printf("%s", machine_eval::FormatSeedsTable(e, o.markdown).c_str());
  std::size_t ok = 0;
  for (const auto& r : e.runs) ok += r.summary.screws - r.summary.failed;
  if (ok == 0) throw CommandFailure("every comparison failed", 1);
}

// Field scenarios (and legacy beside them): one table over seeds (machine_eval/field_eval.h).
void RunScenarios(const MachineCliOptions& o, const std::vector<machine::MachineScenario>& scenarios,
                  const sim::Screw& base, const workpiece::WorkpieceModel& model,
                  const compare::ExperienceRule& rule, const compare::IsoToleranceTable& iso,
                  const machine_eval::MachineEvalOptions& eo) {
  Progress progress("machine evaluate", scenarios.size() * 1000);
  std::vector<machine_eval::SeedsEvaluation> all = machine_eval::EvaluateMachineScenarios(
      scenarios, base, model, rule, iso, eo, FieldOptions(o), o.seeds,
      [&](std::size_t d, std::size_t) { progress.Update(d); });
  progress.Finish();
  std::size_t ok = 0;
  for (auto& e : all) {
    e.travel_c_um = o.travel_c_um;
    for (const auto& r : e.runs) ok += r.summary.screws - r.summary.failed;
  }
  if (o.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& e : all) j.push_back(e);
    PrintJson({{"schema", "whirl.machine_scenarios"}, {"schema_version", 1}, {"scenarios", j}});
  } else {
    std::printf("%s", machine_eval::FormatScenarioTables(all, o.markdown).c_str());
  }
  if (ok == 0) throw CommandFailure("every comparison failed", 1);
}

void RunMachineEvaluate(const MachineCliOptions& o) {
  CheckOutputs({{"--machine-thermal", o.machine_path},
                {"--model", o.model_path},
                {"--history", o.history},
                {"--base-screw", o.base_screw},
                {"--iso-table", o.iso_table},
                {"--profile", o.profile}},
               {}, {{"--out-dir", o.report}});
  const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(o.model_path);
  const compare::ExperienceRule rule =
      compare::BuildExperienceRule(ReadProcessTable(o.history, /*require_targets=*/true));
  const compare::IsoToleranceTable iso = compare::ReadIsoToleranceTable(o.iso_table);
  const sim::Screw base =
      std::filesystem::exists(o.base_screw) ? sim::ReadScrew(o.base_screw) : sim::ReferenceScrew();
  machine_eval::MachineEvalOptions eo;
  eo.machine = LoadMachine(o);
  eo.machines = o.machines;
  eo.screws_per_machine = o.screws;
  eo.train_runs = o.train_runs;
  eo.seed = o.seed;
  eo.threads = o.threads;
  eo.fit.kind = drift::ParseModelKind(o.drift_model);
  eo.fit.selection = ToSelection(o.selection);
  eo.monitor_every_min = o.monitor_every_min;
  eo.report_dir = o.report;
  if (!o.report.empty()) eo.profile = interp::LoadMachineProfile(o.profile);
  const auto scenarios = machine::SelectMachineScenarios(o.scenarios, "--scenarios");
  bool any_legacy = false, any_field = false;
  for (const auto& s : scenarios) (s.world == machine::World::kLegacy ? any_legacy : any_field) = true;
  CheckWorldFlags(o, any_legacy, any_field);
  if (any_field) {
    RunScenarios(o, scenarios, base, model, rule, iso, eo);
    return;
  }
  if (o.seeds > 1) {
    RunOverSeeds(o, base, model, rule, iso, eo);
    return;
  }
  Progress progress("machine evaluate", static_cast<std::size_t>(o.machines * o.screws));
  const machine_eval::MachineEvaluation e = machine_eval::EvaluateWithMachines(
      base, model, rule, iso, eo, [&](std::size_t d, std::size_t) { progress.Update(d); });
  progress.Finish();
  if (o.json) {
    PrintJson(e);
  } else {
    for (std::size_t i = 0; i < e.sensors_cutting.size(); ++i) {
      std::printf("machine %zu sensors (offset model) cutting-trained:", i);
      for (const auto& s : e.sensors_cutting[i]) std::printf(" %s", s.c_str());
      std::printf("; idle-trained:");
      for (const auto& s : e.sensors_idle[i]) std::printf(" %s", s.c_str());
      std::printf("\n");
    }
    std::printf("%s\n%s", e.summary.message.c_str(),
                machine_eval::FormatMachineEvalTable(e, o.markdown).c_str());
  }
  if (!e.programs_note.empty()) Warn(e.programs_note);
  if (!e.report_index.empty())
    std::fprintf(stderr, "report written to %s\n", e.report_index.c_str());
  if (e.summary.failed == e.summary.screws) throw CommandFailure("every comparison failed", 1);
}

void CommonOptions(CLI::App* sub, MachineCliOptions* o) {
  // --machine is the 840D profile in plan and drift nc; here the simulator's thermal machine.
  auto* thermal = sub->add_option("--machine-thermal", o->machine_path,
                                  "the simulated machine's thermal JSON (schema "
                                  "whirl.machine_thermal; default datasets/machines/"
                                  "whirling_thermal.json, built-in default if missing)");
  AddDeprecatedAlias(sub, thermal, "--machine");
  sub->add_flag("--machine-off", o->machine_off,
                "switch every machine component off (m = 0: the workpiece-only truth)");
  sub->add_flag("--json", o->json, "machine output on stdout");
}

// The field scenarios' options (machine/scenarios.h, machine_eval/field_history.h).
void AddScenarioOptions(CLI::App* e, MachineCliOptions* o) {
  e->add_option("--scenarios", o->scenarios,
                "comma list of machine scenarios or 'all': legacy (the closed-form machine, its old "
                "protocol; default), constant-duty, production, duty-changes, interrupted-starts, "
                "unconditioned-hall, linear-scale (the field world: a shop's calendar, models "
                "trained from probe, laser and lead measurements only)");
  auto field = [&](CLI::Option* opt) { o->field_only.push_back(opt); };
  field(e->add_option("--test-days", o->test_days,
                      "field: production days scored per machine (1..20, default 2)")
            ->check(NumberIn(1, 20)));
  field(e->add_option("--past-days", o->past_days,
                      "field: history production days per machine whose screws' leads are "
                      "measured (1..30, default 5)")
            ->check(NumberIn(1, 30)));
  field(e->add_option("--check-every-min", o->check_every_min,
                      "field: probe reading of the check ring every [min] in the warm-up tests "
                      "(1..120, default 10)")
            ->check(NumberIn(1.0, 120.0)));
  field(e->add_option("--probe-noise-um", o->probe_noise_um,
                      "field: standard deviation of one probe reading [um] (0.01..10, default 1)")
            ->check(NumberIn(0.01, 10.0)));
  field(e->add_option("--laser-every-min", o->laser_every_min,
                      "field: laser-interferometer reading every [min] in the Z warm-up test "
                      "(5..120, default 20)")
            ->check(NumberIn(5.0, 120.0)));
  field(e->add_option("--lead-sample-min", o->lead_sample_min,
                      "field: one point of a past screw's measured lead per [min] of cutting "
                      "time in the training record (1..30, default 5)")
            ->check(NumberIn(1.0, 30.0)));
  field(e->add_flag("--no-setup-checks", o->no_setup_checks,
                    "field: no probe reading of the check ring at power-on and at each set-up "
                    "of the past production days"));
}

}  // namespace

void RegisterMachine(CLI::App& app) {
  auto o = std::make_shared<MachineCliOptions>();
  auto* m = app.add_subcommand(
      "machine",
      "The simulated whirling machine's own thermal drift: virtual sensor files (the legacy\n"
      "closed-form machine, src/machine/machine.h), the field world's uncompensated error by\n"
      "source (a shop's days with set-ups, breaks and duty changes; src/machine/truth.h), and the\n"
      "evaluation of both halves of the compensation together against the shop's baselines.");
  m->require_subcommand(1);
  auto* s = m->add_subcommand(
      "sensors",
      "Write virtual-sensor run files (drift format: <name>_C temperatures [degC], offset_um and\n"
      "zscrew_per_1000_um [um]) of one machine: idle warm-ups (ring turning, no cut, 180 min)\n"
      "and cutting runs (150 min); sample step from the machine JSON [min]. Fit them with\n"
      "'whirl drift fit --cutting DIR/cutting_*.csv --error offset_um'; their sensors are the\n"
      "analog inputs of datasets/machines/whirling_840d.json (drift nc --machine).");
  CommonOptions(s, o.get());
  auto* out_dir = s->add_option("--out-dir", o->out,
                                std::string("output folder, all files or none: ") + kOutputDirRule)
                      ->required();
  AddDeprecatedAlias(s, out_dir, "--out");
  AddSeedOption(s, &o->machine_seed, "seed of the machine (default 1)", "--machine-seed");
  s->add_option("--idle", o->idle, "idle warm-up runs (0..20, default 2)")->check(NumberIn(0, 20));
  s->add_option("--cutting", o->cutting, "cutting runs (0..20, default 2)")->check(NumberIn(0, 20));
  s->callback([o] { RunSensors(*o); });

  auto* e = m->add_subcommand(
      "evaluate",
      "Random screws cut on drifting machines (each machine: its own seeded parameters, idle and\n"
      "cutting training runs, MLR drift models on Miao et al.'s sensitive points). Strategies:\n"
      "none, traditional (class means), workpiece (network plan), machine (cutting-trained drift\n"
      "models), both, both_idle (machine model trained on idle warm-ups), both_monitor (offset\n"
      "model kept valid by a check bar, Liu et al.'s patent). Prints median and worst\n"
      "accumulated lead error [um] within 1000 mm and over the thread, P3/P5 shares, the\n"
      "uncompensated error of each source alone and which part dominates what is left.\n"
      "--scenarios (e.g. production,duty-changes or all): the field world (a shop's calendar;\n"
      "models trained only from probe, laser and past screws' lead measurements, applied from\n"
      "past control samples only) with the shop baselines (class, table, nearest, warmup,\n"
      "schedule), machine_shop, both_shop and both_shop_monitor (both_shop kept valid by the\n"
      "probe checks at the test day's set-ups), over --seeds, with the headline against the\n"
      "strongest sensor-free strategy per scenario. Simulator figures only.");
  CommonOptions(e, o.get());
  AddScenarioOptions(e, o.get());
  e->add_option("--machines", o->machines, "machines (1..50, default 2)")->check(NumberIn(1, 50));
  o->legacy_only.push_back(
      e->add_option("--screws", o->screws, "legacy: random screws per machine (1..200, default 3)")
          ->check(NumberIn(1, 200)));
  o->legacy_only.push_back(
      e->add_option("--train-runs", o->train_runs,
                    "legacy: idle and cutting training runs per machine (1..20, default 2)")
          ->check(NumberIn(1, 20)));
  AddSeedOption(e, &o->seed, "seed of machines, days, screws and truth (default 1)");
  e->add_option("--threads", o->threads, "worker threads (1..64, default 2)")
      ->check(NumberIn(1, 64));
  e->add_option("--model", o->model_path, "workpiece model (default models/default.json)")
      ->check(CLI::ExistingFile);
  e->add_option("--history", o->history, "past screws for the traditional rule")
      ->check(CLI::ExistingFile);
  e->add_option("--base-screw", o->base_screw, "screw whose blank and settings are shared");
  e->add_option("--iso-table", o->iso_table, "ISO 3408-3 tolerance table CSV")
      ->check(CLI::ExistingFile);
  o->legacy_only.push_back(e->get_option("--machine-thermal"));
  o->legacy_only.push_back(e->get_option("--machine-off"));
  o->legacy_only.push_back(e->add_option("--drift-model", o->drift_model,
                "machine drift model kind: mlr (Miao et al.'s regression, default) or dynamic "
                "(with first-order lags [min] chosen by cross-validation)")
      ->check(CLI::IsMember({"mlr", "dynamic"})));
  AddSelectionOptions(e, &o->selection);  // Miao et al.'s sensor selection of the machine models
  o->legacy_only.push_back(
      e->add_option("--monitor-every-min", o->monitor_every_min,
                    "legacy both_monitor: check-bar interval of the monitor [min] (1..600, "
                    "default 30)")
          ->check(NumberIn(1.0, 600.0)));
  auto* report = e->add_option(
      "--out-dir", o->report,
      "write the first screw's report into this directory: sensor plot [degC over min], chosen "
      "sensors, lead deviation per strategy [um over mm] and the screw's combined 840D "
      "programs for --profile (" +
          std::string(kOutputDirRule) + ")");
  AddDeprecatedAlias(e, report, "--report");
  o->legacy_only.push_back(report);
  e->add_option("--profile", o->profile,
                "840D machine profile of the combined programs in the report (schema "
                "whirl.machine with drift.slope and drift.workpiece_slope_param; default "
                "datasets/machines/whirling_840d.json, which matches the shipped machine file; a "
                "profile that does not fit the machine leaves the programs out with a warning)")
      ->check(CLI::ExistingFile);
  o->legacy_only.push_back(e->get_option("--profile"));
  e->add_option("--seeds", o->seeds,
                "repeat over seeds S..S+N-1 (new machines, training days and screws each) and "
                "print the pooled table: median [range of per-seed medians] and worst [um], "
                "|e_a - c| median [um], P3/P5 shares, and the headlines against the strongest "
                "sensor-free strategy (1..20, default 1: the single-seed table)")
      ->check(NumberIn(1, 20));
  e->add_option("--travel-c-um", o->travel_c_um,
                "with --seeds: specified travel compensation c of ISO 3408-3 [um] for the "
                "|e_a - c| column (default 0)")
      ->check(FiniteNumber());
  e->add_flag("--markdown", o->markdown, "print the table as Markdown");
  e->callback([o] { RunMachineEvaluate(*o); });
  RegisterMachineTruth(m);
}

}  // namespace whirl::cli
