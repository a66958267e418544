// whirl machine export: one field machine's calendar as files (machine_eval/field_export.h): its
// day logs as drift run files, the shop record's readings, the cuts, and the truth in files named
// as such, with a README of where they came from.
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>

#include "cli/commands.h"
#include "cli/cmd_machine_world.h"
#include "cli/common.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"
#include "machine_eval/field_export.h"
#include "workpiece/model.h"

namespace whirl::cli {
namespace {

struct MachineExportOptions {
  std::string out_dir, scenario = "production";
  std::uint64_t seed = 1;
  int machine_index = 0, past_days = 5, test_days = 2;
  FieldWorldFlags world;
  std::string model_path = ProjectPath("models/default.json");
  std::string history = ProjectPath(kHistoryTable);
  std::string iso_table = ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv");
  bool json = false;
};

std::string ExportCommandLine(const MachineExportOptions& o) {
  std::ostringstream s;
  s << "whirl machine export --out-dir DIR --scenario " << o.scenario << " --seed " << o.seed
    << " --machine-index " << o.machine_index << " --past-days " << o.past_days
    << " --test-days " << o.test_days;
  s << FieldWorldCommandLine(o.world);
  return s.str();
}

std::string ExportReadme(const MachineExportOptions& o, const machine::MachineScenario& sc,
                         const machine::MachineWorld& w,
                         const machine_eval::FieldProtocol& p) {
  const machine::FieldMachineConfig& c = w.timeline.machine().config();
  std::ostringstream s;
  s << "# Field world export (simulator data, not a measured machine)\n\n"
    << "Written by whirl (src/lab/machine_eval/field_export.h describes every file):\n\n    "
    << ExportCommandLine(o) << "\n\n"
    << "- scenario: " << sc.name << ": " << sc.description << "\n"
    << "- seed " << o.seed << ", machine " << o.machine_index << " (machine seed "
    << w.machine_seed << "): the same machine, calendar and records as machine " << o.machine_index
    << " of `whirl machine evaluate --scenarios " << sc.name << " --seed " << o.seed
    << " --past-days " << o.past_days << " --test-days " << o.test_days << "`\n"
    << "- machine: " << c.name << ", Z feedback " << machine::ToString(c.z.feedback)
    << ", blank lag " << (c.blank_h_w_m2k > 0 ? "from its diameter, h = " +
                                                    FormatNumber(c.blank_h_w_m2k) + " W/(m^2 K)"
                                              : FormatNumber(c.blank_tau_min) + " min")
    << ", stock offset std " << FormatNumber(c.stock_offset_std_k) << " K\n"
    << "- hall: " << sc.hall.kind << ", amplitude " << FormatNumber(sc.hall.amplitude_k)
    << " K, day offset std " << FormatNumber(sc.hall.day_offset_std_k) << " K, door events "
    << FormatNumber(sc.hall.door_events_per_day) << " per day\n"
    << "- hall seasons: amplitude " << FormatNumber(sc.hall.seasonal_amplitude_k)
    << " K, warmest on day " << FormatNumber(sc.hall.seasonal_peak_day)
    << "; blank contact reading: "
    << (c.blank_contact_std_k >= 0 ? "sigma " + FormatNumber(c.blank_contact_std_k) + " K"
                                   : std::string("none"))
    << "; test days' shift pattern: "
    << (o.world.test_shift_of.empty() ? sc.name : o.world.test_shift_of) << "\n"
    << "- instruments: probe at z = " << FormatNumber(p.probe_z_mm) << " mm (sigma "
    << FormatNumber(p.probe_sigma_um) << " um, every " << FormatNumber(p.check_every_min)
    << " min in a warm-up test), laser every " << FormatNumber(p.laser_every_min)
    << " min, one lead point per " << FormatNumber(p.lead_sample_min)
    << " min of cutting; history logs every " << FormatNumber(p.log_sample_s)
    << " s, test-day logs every control sample\n"
    << "- the evaluation's control averages every temperature over the last "
    << FormatNumber(p.sensor_average_min) << " min; the logs here hold the raw readings\n\n"
    << "Files: days.csv (calendar), day<d>_<role>.csv (day logs, drift run files), records.csv "
       "(probe, laser, lead and set-up check readings), cuts.csv (the cuts as planned); "
       "truth_*.csv: TRUTH, which no instrument sees (for scoring only).\n\n"
    << "Try: `whirl drift fit --idle day-0NN_warmup_test.csv ... --cutting "
       "day-0NN_history.csv ... --error check_ring_um --out model.json`, then `whirl drift "
       "predict --model model.json --run day+000_test.csv`.\n";
  return s.str();
}

void RunMachineExport(const MachineExportOptions& o) {
  CheckOutputs({{"--model", o.model_path}, {"--history", o.history}, {"--iso-table", o.iso_table}},
               {}, {{"--out-dir", o.out_dir}});
  std::vector<machine::MachineScenario> scenarios =
      machine::SelectMachineScenarios(o.scenario, "--scenario");
  if (scenarios.size() != 1) throw InputError("--scenario '" + o.scenario + "': one scenario name");
  OutputDir out(o.out_dir, "--out-dir");
  const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(o.model_path);
  const compare::ExperienceRule rule =
      compare::BuildExperienceRule(ReadProcessTable(o.history, /*require_targets=*/true));
  const lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(o.iso_table);
  machine_eval::FieldEvalOptions f;  // the evaluation's defaults: the same world
  f.seed = o.seed;
  f.calendar.past_days = o.past_days;
  f.calendar.test_days = o.test_days;
  ApplyFieldWorld(o.world, &f, &scenarios);
  const machine::MachineScenario& scenario = scenarios.front();
  const machine::MachineWorld world = machine::BuildMachineWorld(
      f.machine, scenario, f.seed, o.machine_index, f.calendar, f.timeline);
  const machine_eval::WorkpieceResidual residual =
      machine_eval::FieldHistoryResidual(world.timeline, model, rule, iso, f.compare);
  machine_eval::ExportTruthRange range;
  range.z_ref_mm = world.timeline.machine().config().z.fixed_end_mm;
  const auto files = machine_eval::FieldExportFiles(
      world.timeline, f.protocol, residual, machine_eval::ShopRecordSeed(world.machine_seed),
      range, ExportReadme(o, scenario, world, f.protocol));
  for (const auto& [name, text] : files) out.Add(name, text);
  const auto paths = out.Commit();
  if (o.json) {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& p : paths) j.push_back(p.string());
    PrintJson({{"schema", "whirl.machine_export"}, {"schema_version", 1}, {"files", j}});
    return;
  }
  std::printf("%zu files written to %s (days.csv, day logs, records.csv, cuts.csv, truth_*.csv, "
              "README.md)\n",
              paths.size(), o.out_dir.c_str());
}

}  // namespace

void RegisterMachineExport(CLI::App* machine) {
  auto o = std::make_shared<MachineExportOptions>();
  auto* s = machine->add_subcommand(
      "export",
      "Write one field machine's calendar as files for other tools (simulator data): every day's\n"
      "log as a drift run file (time_min [abs min], <sensor>_C [degC] as read, the control's\n"
      "duty signals, check_ring_um [um]: a displacement sensor on the check ring, zeroed at the\n"
      "day's first row), records.csv (the probe, laser, lead and set-up check readings the\n"
      "evaluation's models learn from [um]), days.csv, cuts.csv, and the TRUTH in truth_*.csv\n"
      "(the machine's error [um], the hall and the blank [degC]); README.md says where they came\n"
      "from. Machine --machine-index of 'whirl machine evaluate' with the same --scenarios, --seed,\n"
      "--past-days and --test-days. All files or none.");
  s->add_option("--out-dir", o->out_dir,
                std::string("output folder, all files or none: ") + kOutputDirRule)
      ->required();
  s->add_option("--scenario", o->scenario,
                "machine scenario (default production; see 'whirl machine evaluate --help')");
  AddSeedOption(s, &o->seed, "seed of machines, calendars, screws and truth (default 1)");
  s->add_option("--machine-index", o->machine_index,
                "which machine of the seed (0..19, default 0)")
      ->check(NumberIn(0, 19));
  s->add_option("--past-days", o->past_days,
                "history production days (1..40, default 5)")
      ->check(NumberIn(1, 40));
  s->add_option("--test-days", o->test_days, "test production days (1..20, default 2)")
      ->check(NumberIn(1, 20));
  AddFieldWorldOptions(s, &o->world);
  s->add_option("--model", o->model_path,
                "workpiece model of the history screws' plan (default models/default.json)")
      ->check(CLI::ExistingFile);
  s->add_option("--history", o->history, "past screws for the traditional rule")
      ->check(CLI::ExistingFile);
  s->add_option("--iso-table", o->iso_table, "ISO 3408-3 tolerance table CSV")
      ->check(CLI::ExistingFile);
  s->add_flag("--json", o->json, "machine output on stdout: the files written");
  s->callback([o] { RunMachineExport(*o); });
}

}  // namespace whirl::cli
