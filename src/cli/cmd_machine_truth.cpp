// whirl machine truth: the field machine's uncompensated error per cut, split by source, for the
// chosen scenarios (src/lab/machine/magnitudes.h). A check of the simulated world, not an evaluation.
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/common.h"
#include "machine/magnitudes.h"
#include "machine/scenarios.h"

namespace whirl::cli {
namespace {

struct MachineTruthOptions {
  std::string scenarios = "all";
  std::uint64_t seed = 1;
  int machines = 2, test_days = 2, past_days = 5;
  bool markdown = false;
  bool json = false;
};

// --json: every test-day cut of every scenario, figures in um.
nlohmann::json MachineTruthJson(const std::vector<machine::ScenarioMagnitudes>& rows) {
  nlohmann::json scenarios = nlohmann::json::array();
  for (const auto& row : rows) {
    nlohmann::json cuts = nlohmann::json::array();
    for (const auto& c : row.cuts)
      cuts.push_back({{"machine", c.machine},
                      {"day", c.day},
                      {"job", c.job},
                      {"start_type", machine::ToString(c.start_type)},
                      {"head_thread_um", c.head_thread_um},
                      {"z_thread_um", c.z_thread_um},
                      {"total_thread_um", c.total_thread_um},
                      {"head_1000_um", c.head_1000_um},
                      {"z_1000_um", c.z_1000_um},
                      {"total_1000_um", c.total_1000_um},
                      {"hall_slope_k_per_h", c.hall_slope_k_per_h}});
    scenarios.push_back({{"scenario", row.scenario}, {"cuts", cuts}});
  }
  return {{"schema", "whirl.machine_truth"}, {"schema_version", 1}, {"scenarios", scenarios}};
}

void RunMachineTruth(const MachineTruthOptions& o) {
  std::vector<machine::ScenarioMagnitudes> rows;
  machine::CalendarSpec spec;
  spec.test_days = o.test_days;
  spec.past_days = o.past_days;
  for (const auto& s : machine::SelectMachineScenarios(o.scenarios, "--scenarios")) {
    std::fprintf(stderr, "scenario %s...\n", s.name.c_str());
    rows.push_back(machine::MeasureMagnitudes(machine::DefaultFieldMachine(), s, o.seed,
                                              o.machines, spec));
  }
  if (o.json)
    PrintJson(MachineTruthJson(rows));
  else
    std::fputs(machine::FormatMagnitudes(rows, o.markdown).c_str(), stdout);
}

}  // namespace

void RegisterMachineTruth(CLI::App* machine) {
  auto o = std::make_shared<MachineTruthOptions>();
  auto* t = machine->add_subcommand(
      "truth",
      "Uncompensated machine error of the field world per test-day cut, split by source (head,\n"
      "Z axis), band width [um] within 1000 mm and over the thread, median / worst, and by start\n"
      "type (cold, warm, interrupted, long_pause). The truth side only: no model is trained.");
  t->add_option("--scenarios", o->scenarios,
                "comma list of machine scenarios or 'all' (default all)");
  AddSeedOption(t, &o->seed, "seed of machines, calendars and halls (default 1)");
  t->add_option("--machines", o->machines, "machines (1..20, default 2)")->check(NumberIn(1, 20));
  t->add_option("--test-days", o->test_days, "production days in the test window (1..20, default 2)")
      ->check(NumberIn(1, 20));
  t->add_option("--past-days", o->past_days, "history production days (0..30, default 5)")
      ->check(NumberIn(0, 30));
  t->add_flag("--markdown", o->markdown, "print the table as Markdown");
  t->add_flag("--json", o->json, "machine output: every cut's figures [um] as JSON on stdout");
  t->callback([o] { RunMachineTruth(*o); });
}

}  // namespace whirl::cli
