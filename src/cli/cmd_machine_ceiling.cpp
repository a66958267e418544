// whirl machine ceiling: what a regression trained on the machine's exact truth could reach with
// each feature set, beside the shop's estimators (machine_eval/ceiling.h).
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/cmd_machine_world.h"
#include "cli/common.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "machine/scenarios.h"
#include "machine_eval/ceiling.h"
#include "workpiece/model.h"

namespace whirl::cli {
namespace {

struct MachineCeilingOptions {
  std::string scenarios = "production";
  std::uint64_t seed = 1;
  int seeds = 1, machines = 4, past_days = 40, test_days = 10, estimator_past_days = 5;
  int threads = 1;
  double row_step_min = 1;
  FieldWorldFlags world;
  std::string model_path = ProjectPath("models/default.json");
  std::string history = ProjectPath(kHistoryTable);
  std::string iso_table = ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv");
  bool json = false, grey_structure = false;
};

nlohmann::json CeilingJson(const std::vector<machine_eval::CeilingScenario>& rows) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& r : rows) {
    nlohmann::json cuts = nlohmann::json::array();
    for (const auto& c : r.cuts)
      cuts.push_back({{"machine", c.machine},
                      {"day", c.day},
                      {"job", c.job},
                      {"ceiling_um", c.ceiling_um},
                      {"estimator_um", c.estimator_um},
                      {"grey_um", c.grey_um},
                      {"blank_error_k", c.blank_error_k}});
    j.push_back({{"scenario", r.scenario},
                 {"seeds", r.seeds},
                 {"ceiling_median_um", r.ceiling_median_um},
                 {"estimator_median_um", r.estimator_median_um},
                 {"grey_median_um", r.grey_median_um},
                 {"blank_error_median_k", r.blank_error_median_k},
                 {"blank_error_p95_k", r.blank_error_p95_k},
                 {"cuts", cuts}});
  }
  return {{"schema", "whirl.machine_ceiling"},
          {"schema_version", 1},
          {"feature_sets", machine_eval::CeilingFeatureSets()},
          {"estimators", machine_eval::CeilingEstimators()},
          {"grey_columns", machine_eval::CeilingGreyColumns()},
          {"blank_models", machine_eval::CeilingBlankModels()},
          {"scenarios", j}};
}

void RunMachineCeiling(const MachineCeilingOptions& o) {
  CheckOutputs({{"--model", o.model_path}, {"--history", o.history}, {"--iso-table", o.iso_table}},
               {}, {});
  if (o.estimator_past_days > o.past_days)
    throw InputError("--estimator-past-days " + std::to_string(o.estimator_past_days) +
                     ": must not exceed --past-days " + std::to_string(o.past_days));
  auto scenarios = machine::SelectMachineScenarios(o.scenarios, "--scenarios");
  const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(o.model_path);
  const compare::ExperienceRule rule =
      compare::BuildExperienceRule(ReadProcessTable(o.history, /*require_targets=*/true));
  const lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(o.iso_table);
  machine_eval::CeilingOptions c;
  c.field.seed = o.seed;
  c.field.machines = o.machines;
  c.field.threads = o.threads;
  c.field.calendar.past_days = o.past_days;
  c.field.calendar.test_days = o.test_days;
  ApplyFieldWorld(o.world, &c.field, &scenarios);
  c.estimator_past_days = o.estimator_past_days;
  c.row_step_min = o.row_step_min;
  c.grey_structure = o.grey_structure;
  std::vector<machine_eval::CeilingScenario> rows;
  Progress progress("machine ceiling", scenarios.size() * 1000);
  for (std::size_t i = 0; i < scenarios.size(); ++i)
    rows.push_back(machine_eval::EvaluateCeiling(
        scenarios[i], model, rule, iso, c, o.seeds, [&](std::size_t done, std::size_t total) {
          if (total) progress.Update(i * 1000 + 1000 * done / total);
        }));
  progress.Finish();
  if (o.json) {
    PrintJson(CeilingJson(rows));
    return;
  }
  std::printf("%s", machine_eval::FormatCeilingTable(rows).c_str());
  if (o.grey_structure)
    std::printf("\n%s", machine_eval::FormatGreyStructureTable(rows).c_str());
}

}  // namespace

void RegisterMachineCeiling(CLI::App* machine) {
  auto o = std::make_shared<MachineCeilingOptions>();
  auto* s = machine->add_subcommand(
      "ceiling",
      "The ceiling of the machine half (simulator figures only): per scenario a regression in\n"
      "the 840D form (offset and slope per 1000 mm) trained on the machine's EXACT error along\n"
      "every cut of --past-days production days, with the feature sets none, time (lags of\n"
      "power-on), time+duty, joint (sensor rises and lags), absolute (absolute temperatures,\n"
      "lags, time, duty) and +blank (the blank's true temperature at the cut start), beside the\n"
      "shop's models trained on what the shop measures over the last --estimator-past-days\n"
      "(uncompensated, warmup, schedule, sensors = both_shop's machine half, grey = both_grey's).\n"
      "Prints the median accumulated lead error of the machine half over the thread [um] of\n"
      "every test-day cut (machine_eval/ceiling.h).");
  s->add_option("--scenarios", o->scenarios,
                "comma list of machine scenarios or 'all' (default production; see 'whirl machine "
                "evaluate --help')");
  AddSeedOption(s, &o->seed, "first seed of machines, calendars and truth (default 1)");
  s->add_option("--seeds", o->seeds, "seeds S..S+N-1 (1..20, default 1)")->check(NumberIn(1, 20));
  s->add_option("--machines", o->machines, "machines per scenario and seed (1..20, default 4)")
      ->check(NumberIn(1, 20));
  s->add_option("--past-days", o->past_days,
                "production days the ceiling trains on (1..40, default 40)")
      ->check(NumberIn(1, 40));
  s->add_option("--test-days", o->test_days, "production days scored (1..20, default 10)")
      ->check(NumberIn(1, 20));
  s->add_option("--estimator-past-days", o->estimator_past_days,
                "the shop's models learn from the last this many past days (1..40, not above "
                "--past-days; default 5)")
      ->check(NumberIn(1, 40));
  s->add_option("--row-step-min", o->row_step_min,
                "one training row per [min] along a past cut (0.1..30, default 1)")
      ->check(NumberIn(0.1, 30.0, "min"));
  AddFieldWorldOptions(s, &o->world);
  s->add_option("--threads", o->threads, "worker threads over machines (1..64, default 1)")
      ->check(NumberIn(1, 64));
  s->add_option("--model", o->model_path, "workpiece model (default models/default.json)")
      ->check(CLI::ExistingFile);
  s->add_option("--history", o->history, "past screws for the traditional rule")
      ->check(CLI::ExistingFile);
  s->add_option("--iso-table", o->iso_table, "ISO 3408-3 tolerance table CSV")
      ->check(CLI::ExistingFile);
  s->add_flag("--grey-structure", o->grey_structure,
             "also the grey box's own structure trained on the exact truth (its sensors, lags, "
             "priors; with the true blank; with every sensor; on the last --estimator-past-days), "
             "a second table with the gaps of the shop's grey box to the ceiling and the error of "
             "its latched blank estimate [K]");
  s->add_flag("--json", o->json, "machine output on stdout: every cut's figures [um]");
  s->callback([o] { RunMachineCeiling(*o); });
}

}  // namespace whirl::cli
