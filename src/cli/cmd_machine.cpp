// whirl machine: the simulated whirling machine, the field world (src/lab/machine/,
// src/lab/machine_eval/machine_eval.h).
//   whirl machine sensors   --out-dir DIR   day logs of one field machine (drift run files)
//   whirl machine truth                     uncompensated error by source (cmd_machine_truth.cpp)
//   whirl machine evaluate                  both halves over scenarios and seeds; --out-dir: the
//                                           first test-day screw's report (machine_report/)
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "cli/cmd_machine_world.h"
#include "cli/common.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "drift/run_file.h"
#include "interp/machine_profile.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"
#include "machine_report/machine_report.h"
#include "workpiece/model.h"

namespace whirl::cli {
namespace {

/// Flags of the retired legacy world (a closed-form machine with exact error channels): hidden,
/// and given they fail naming what replaced them.
constexpr const char* kRetired =
    "applied to the legacy machine world, which was retired (docs/machine-evaluation.md): the "
    "field world's machines, days and screws come from --scenarios, --machines, --test-days and "
    "--past-days";

struct MachineCliOptions {
  std::uint64_t machine_seed = 1, seed = 1;
  // sensors
  std::string out;
  std::string scenario = "production";
  int idle = 2, cutting = 2;
  double probe_z_mm = 150, displacement_noise_um = 0.5;
  // evaluate
  std::string model_path = ProjectPath("models/default.json");
  std::string history = ProjectPath(kHistoryTable);
  std::string iso_table = ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv");
  int machines = 2, threads = 2;
  bool markdown = false, json = false;
  int seeds = 1;
  double travel_c_um = 0;
  std::string report;
  std::string profile = ProjectPath("datasets/machines/whirling_840d.json");
  std::string scenarios = "production";
  int test_days = 2, past_days = 5;
  double check_every_min = 10, probe_noise_um = 1.0, laser_every_min = 20, lead_sample_min = 5;
  bool no_setup_checks = false, slope_through_lags_only = false, offset_candidates = false,
       grey_candidates = false, grey_five_sensors = false, grey_without_short_mix = false;
  FieldWorldFlags world;  ///< the world's optional parts (cmd_machine_world.h)
  std::vector<std::pair<std::string, CLI::Option*>> retired;  ///< legacy-world flags, hidden
};

// A flag of the retired legacy world, hidden; CheckRetired fails when one was given.
void AddRetired(CLI::App* sub, MachineCliOptions* o, const std::vector<std::string>& flags) {
  for (const auto& f : flags)
    o->retired.emplace_back(f, sub->add_option(f)->expected(0, 1)->group(""));
}

void CheckRetired(const MachineCliOptions& o) {
  for (const auto& [flag, opt] : o.retired)
    if (opt->count() > 0) throw InputError(flag + ": " + kRetired);
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
  f.protocol.grey_slope_lags_only = o.slope_through_lags_only;
  f.protocol.offset_candidates = o.offset_candidates;
  f.protocol.grey_candidates = o.grey_candidates;
  f.protocol.grey_five_sensors = o.grey_five_sensors;
  f.protocol.grey_short_mix = !o.grey_without_short_mix;
  return f;
}

// The warm-up tests (idle) and past production days (cutting) of machine 0 of the scenario, as
// drift run files with the check ring's displacement (machine/instruments.h CheckRingLog).
void RunSensors(const MachineCliOptions& o) {
  CheckRetired(o);
  CheckOutputs({}, {}, {{"--out-dir", o.out}});
  const std::vector<drift::Run> runs =
      machine::ShopDayLogs(machine::FindMachineScenario(o.scenario), o.machine_seed, o.idle,
                           o.cutting, o.probe_z_mm, o.displacement_noise_um);
  const std::vector<std::string> comments = {
      "simulated by: whirl machine sensors --scenario " + o.scenario + " --machine-seed " +
          std::to_string(o.machine_seed) +
          " (the field world, src/lab/machine/; idle: warm-up tests, cutting: production days)",
      "time_min since the day's 00:00; <sensor>_C as the sensors read; power_on, ring_on, "
      "ring_rpm, ring_load_pct, cutting, z_speed_mm_min, z_position_mm, clock_min: the control's "
      "duty signals",
      "offset_um: a displacement sensor on the check ring at z = " +
          std::to_string(static_cast<int>(o.probe_z_mm)) +
          " mm, zeroed at power-on (a shop logs this on warm-up tests; while cutting it reads the "
          "ring only at set-ups)"};
  const auto paths = drift::WriteRuns(o.out, runs, comments, "--out-dir");
  if (o.json) {
    nlohmann::json files = nlohmann::json::array();
    for (std::size_t k = 0; k < paths.size(); ++k)
      files.push_back({{"path", paths[k].string()}, {"state", drift::ToString(runs[k].state)}});
    PrintJson({{"schema", "whirl.machine_sensors"}, {"schema_version", 2}, {"files", files}});
    return;
  }
  for (std::size_t k = 0; k < paths.size(); ++k)
    std::printf("%s (%s, %d samples)\n", paths[k].string().c_str(),
                drift::ToString(runs[k].state).c_str(), runs[k].samples());
}

// The report of the evaluation's report screw (machine_report/); a profile that does not fit the
// machine leaves the programs out with a warning.
void WriteReport(const MachineCliOptions& o, const machine_eval::SeedsEvaluation& first) {
  const auto& report = first.runs.front().report;
  if (!report) {
    Warn("--out-dir: no test-day screw of machine 0 was evaluated without error: no report");
    return;
  }
  const interp::MachineProfile profile = interp::LoadMachineProfile(o.profile);
  const machine_report::MachineReport r =
      machine_report::WriteMachineScrewReport(o.report, *report, &profile);
  if (!r.programs_note.empty()) Warn(r.programs_note);
  if (!r.mix_note.empty()) Warn(r.mix_note);
  std::fprintf(stderr, "report written to %s\n", r.index_html.c_str());
}

void RunMachineEvaluate(const MachineCliOptions& o) {
  CheckRetired(o);
  CheckOutputs({{"--model", o.model_path},
                {"--history", o.history},
                {"--iso-table", o.iso_table},
                {"--profile", o.profile}},
               {}, {{"--out-dir", o.report}});
  const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(o.model_path);
  const compare::ExperienceRule rule =
      compare::BuildExperienceRule(ReadProcessTable(o.history, /*require_targets=*/true));
  const lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(o.iso_table);
  auto scenarios = machine::SelectMachineScenarios(o.scenarios, "--scenarios");
  machine_eval::FieldEvalOptions f = FieldOptions(o);
  ApplyFieldWorld(o.world, &f, &scenarios);
  f.keep_report_screw = !o.report.empty();
  Progress progress("machine evaluate", scenarios.size() * 1000);
  std::vector<machine_eval::SeedsEvaluation> all = machine_eval::EvaluateMachineScenarios(
      scenarios, model, rule, iso, f, o.seeds,
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
    PrintJson({{"schema", "whirl.machine_scenarios"}, {"schema_version", 2}, {"scenarios", j}});
  } else {
    std::printf("%s", machine_eval::FormatScenarioTables(all, o.markdown).c_str());
  }
  if (!o.report.empty()) WriteReport(o, all.front());
  if (ok == 0) throw CommandFailure("every comparison failed", 1);
}

// The field world's options (machine/scenarios.h, machine_eval/field_history.h).
void AddScenarioOptions(CLI::App* e, MachineCliOptions* o) {
  e->add_option("--scenarios", o->scenarios,
                "comma list of machine scenarios or 'all': constant-duty, production (default), "
                "duty-changes, interrupted-starts, unconditioned-hall, linear-scale (a shop's "
                "calendar on the field machine; models trained from probe, laser and lead "
                "measurements only)");
  e->add_option("--test-days", o->test_days,
                "production days scored per machine (1..20, default 2)")
      ->check(NumberIn(1, 20));
  e->add_option("--past-days", o->past_days,
                "history production days per machine whose screws' leads are measured (1..40, "
                "default 5; 40 = 8 weeks)")
      ->check(NumberIn(1, 40));
  e->add_option("--check-every-min", o->check_every_min,
                "probe reading of the check ring every [min] in the warm-up tests (1..120, "
                "default 10)")
      ->check(NumberIn(1.0, 120.0));
  e->add_option("--probe-noise-um", o->probe_noise_um,
                "standard deviation of one probe reading [um] (0.01..10, default 1)")
      ->check(NumberIn(0.01, 10.0));
  e->add_option("--laser-every-min", o->laser_every_min,
                "laser-interferometer reading every [min] in the Z warm-up test (5..120, "
                "default 20)")
      ->check(NumberIn(5.0, 120.0));
  e->add_option("--lead-sample-min", o->lead_sample_min,
                "one point of a past screw's measured lead per [min] of cutting time in the "
                "training record (1..30, default 5)")
      ->check(NumberIn(1.0, 30.0));
  AddFieldWorldOptions(e, &o->world);
  e->add_flag("--no-setup-checks", o->no_setup_checks,
              "no probe reading of the check ring at power-on and at each set-up of the past "
              "production days");
}

void RegisterSensors(CLI::App* m, const std::shared_ptr<MachineCliOptions>& o) {
  auto* s = m->add_subcommand(
      "sensors",
      "Write the day logs of one field machine (machine 0 of --scenario) as drift run files:\n"
      "<sensor>_C temperatures [degC], the control's duty signals, and offset_um [um], a\n"
      "displacement sensor on the check ring at --probe-z-mm, zeroed at power-on; idle_<n>.csv:\n"
      "the warm-up tests (ring idle at 150..210 m/min, 180 min), cutting_<n>.csv: the\n"
      "scenario's production days; one row per minute, time_min since the day's 00:00. Fit them\n"
      "with 'whirl drift fit --cutting DIR/cutting_*.csv --error offset_um'. Simulator data.");
  auto* out_dir = s->add_option("--out-dir", o->out,
                                std::string("output folder, all files or none: ") + kOutputDirRule)
                      ->required();
  AddDeprecatedAlias(s, out_dir, "--out");
  s->add_option("--scenario", o->scenario,
                "machine scenario of the days (default production; see 'whirl machine evaluate "
                "--help')");
  AddSeedOption(s, &o->machine_seed, "seed of the machine (default 1)", "--machine-seed");
  s->add_option("--idle", o->idle, "warm-up tests (0..20, default 2)")->check(NumberIn(0, 20));
  s->add_option("--cutting", o->cutting, "production days (0..20, default 2)")
      ->check(NumberIn(0, 20));
  s->add_option("--probe-z-mm", o->probe_z_mm,
                "position of the check ring [mm from the chuck face] (0..6000, default 150)")
      ->check(NumberIn(0.0, 6000.0, "mm"));
  s->add_option("--displacement-noise-um", o->displacement_noise_um,
                "standard deviation of one displacement reading [um] (0..10, default 0.5)")
      ->check(NumberIn(0.0, 10.0, "um"));
  s->add_flag("--json", o->json, "machine output on stdout");
  AddRetired(s, o.get(), {"--machine", "--machine-off"});
  s->callback([o] { RunSensors(*o); });
}

void RegisterEvaluate(CLI::App* m, const std::shared_ptr<MachineCliOptions>& o) {
  auto* e = m->add_subcommand(
      "evaluate",
      "Both halves of the compensation on the field world: per machine of each scenario a shop's\n"
      "calendar (warm-up tests, a laser test, --past-days production days) gives the only\n"
      "training data (probe, laser and the measured leads of past screws); the screws of\n"
      "--test-days production days are cut with every strategy: none, traditional (the\n"
      "strongest history rule), workpiece (the network's plan), class, table, nearest, warmup\n"
      "(time since power-on), schedule (the control's duty signals), lead_slope, machine_shop\n"
      "(the sensor model alone), both_shop (plan + sensor model), both_shop_monitor\n"
      "(both_shop kept valid by the probe checks at the set-ups) and both_grey (plan + the\n"
      "grey box: absolute temperatures, a slope intercept, the blank latched at the cut start,\n"
      "physical priors), every machine model applied\n"
      "from past control samples only. Prints per scenario the median [range of per-seed\n"
      "medians] and worst accumulated lead error [um] within 1000 mm and over the thread,\n"
      "|e_a - c| [um], P3/P5 shares, and the headlines against the strongest sensor-free\n"
      "strategy. Simulator figures only.");
  e->add_flag("--json", o->json, "machine output on stdout");
  AddScenarioOptions(e, o.get());
  e->add_option("--machines", o->machines, "machines per scenario and seed (1..20, default 2)")
      ->check(NumberIn(1, 20));
  AddSeedOption(e, &o->seed, "seed of machines, calendars, screws and truth (default 1)");
  e->add_option("--threads", o->threads, "worker threads (1..64, default 2)")
      ->check(NumberIn(1, 64));
  e->add_option("--model", o->model_path, "workpiece model (default models/default.json)")
      ->check(CLI::ExistingFile);
  e->add_option("--history", o->history, "past screws for the traditional rule")
      ->check(CLI::ExistingFile);
  e->add_option("--iso-table", o->iso_table, "ISO 3408-3 tolerance table CSV")
      ->check(CLI::ExistingFile);
  auto* report = e->add_option(
      "--out-dir", o->report,
      "write the report of the first scenario's first test-day screw (machine 0, first seed) "
      "into this directory: its control log [degC over min], the sensor model's sensors, lead "
      "deviation per strategy [um over mm] and the combined 840D programs for --profile of the "
      "models a shop can train (the network's plan and the grey box of both_grey wherever it "
      "was fitted, else both_shop's sensor model) (" +
          std::string(kOutputDirRule) + ")");
  AddDeprecatedAlias(e, report, "--report");
  e->add_option("--profile", o->profile,
                "840D machine profile of the combined programs in the report (schema "
                "whirl.machine with drift.slope, drift.workpiece_slope_param and the analog inputs "
                "of the sensors and duty signals; default datasets/machines/whirling_840d.json, "
                "which matches the field machine; a profile that does not fit the machine leaves "
                "the programs out with a warning)")
      ->check(CLI::ExistingFile);
  e->add_option("--seeds", o->seeds,
                "repeat over seeds S..S+N-1 (new machines, calendars and screws each) and print "
                "the pooled table: median [range of per-seed medians] and worst [um], |e_a - c| "
                "median [um], P3/P5 shares, and the headlines against the strongest sensor-free "
                "strategy (1..20, default 1)")
      ->check(NumberIn(1, 20));
  e->add_option("--travel-c-um", o->travel_c_um,
                "specified travel compensation c of ISO 3408-3 [um] for the |e_a - c| column "
                "(default 0)")
      ->check(FiniteNumber());
  e->add_flag("--markdown", o->markdown, "print the table as Markdown");
  e->add_flag("--slope-through-lags-only", o->slope_through_lags_only,
              "both_grey's slope sensors (ambient, z_nut) through their lags only, the offset's "
              "as read: an opt-in variant, off by default, that lost on its tuning seeds "
              "(docs/machine-history.md, sixth round)");
  e->add_flag("--grey-five-sensors", o->grey_five_sensors,
              "both_grey with its five physical sensors on every record: the model before the "
              "eleventh round, which takes every sensor once the record holds 20 lead days; "
              "opt-in, so that older figures reproduce (docs/machine-history.md, eleventh "
              "round)");
  e->add_flag("--grey-without-short-mix", o->grey_without_short_mix,
              "both_grey as the grey box's line alone on a record of fewer than 20 lead days: "
              "the default before the fourteenth round, which mixes it with the sensor-free "
              "base rule there (w grey + (1 - w) rule, w from the shop's last two lead days "
              "within [0.5, 1]); opt-out, so that older figures reproduce bit for bit "
              "(docs/machine-history.md, fourteenth round)");
  e->add_flag("--offset-candidates", o->offset_candidates,
              "two more rows after the table's, computed in the same run: both_grey's slope with "
              "warmup's offset K0 (grey_warmup_k0) and with the mean of both offsets "
              "(grey_mean_k0); opt-in, off by default; both lost on their tuning seeds "
              "(docs/machine-history.md, seventh round)");
  e->add_flag("--grey-candidates", o->grey_candidates,
              "the opt-in grey rows after the table's (with the --offset-candidates rows), "
              "computed in the same run from the same records: grey_all_sensors (the grey box "
              "with every sensor on both channels), grey_sensors_by_days (grey_all_sensors' "
              "model once the record holds 20 lead days, both_grey's before), grey_short_prior "
              "(both_grey with the prior strength fixed at 1 while the record holds fewer than "
              "20 lead days), grey_short_offset_as_read and grey_short_offset_one_lag "
              "(both_grey with the offset sensors as read, or through the shortest chosen lag, "
              "while the record holds fewer than 20 lead days) and grey_guarded (both_grey's "
              "model or the sensor-free base rule, whichever predicted the shop's own last two "
              "lead days better), grey_short_mix and grey_short_mix_fixed (while the record "
              "holds fewer than 20 lead days the line w both_grey + (1 - w) the base rule, w "
              "from the same two lead days, at least 0.5, or fixed at 0.75); off by default "
              "(docs/machine-history.md, eighth to fourteenth rounds)");
  AddRetired(e, o.get(),
             {"--screws", "--train-runs", "--machine", "--machine-off", "--drift-model",
              "--monitor-every-min", "--base-screw", "--alpha", "--classes", "--max-sensors"});
  e->callback([o] { RunMachineEvaluate(*o); });
}

}  // namespace

void RegisterMachine(CLI::App& app) {
  auto o = std::make_shared<MachineCliOptions>();
  auto* m = app.add_subcommand(
      "machine",
      "The simulated whirling machine's own thermal drift, the field world (a machine as a\n"
      "thermal network living a shop's calendar: set-ups, breaks, duty changes, halls;\n"
      "src/lab/machine/): its day logs as drift run files, its uncompensated error by source,\n"
      "and the evaluation of both halves of the compensation against the shop's baselines.");
  m->require_subcommand(1);
  RegisterSensors(m, o);
  RegisterEvaluate(m, o);
  RegisterMachineTruth(m);
  RegisterMachineExport(m);
  RegisterMachineCeiling(m);
}

}  // namespace whirl::cli
