// whirl dataset: simulated process tables for training and validation (src/lab/sim/dataset.h).
#include <filesystem>
#include <iostream>
#include <sstream>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/curve.h"
#include "core/output_dir.h"
#include "sim/dataset.h"

namespace whirl::cli {
namespace {

struct DatasetCliOptions {
  int count = 20;
  std::uint64_t seed = 1;
  std::string out_path;
  std::string curves_dir;
  double window_s = sim::DatasetOptions{}.window_s;
  int threads = 2;
  bool no_disturbances = false;
  bool json = false;
};

void Run(const DatasetCliOptions& o) {
  CheckOutputs({}, {{"--out", o.out_path}}, {{"--curves-dir", o.curves_dir}});
  sim::DatasetOptions options;
  options.count = o.count;
  options.seed = o.seed;
  options.window_s = o.window_s;
  options.threads = o.threads;
  options.disturbance.enabled = !o.no_disturbances;
  Progress progress("dataset", static_cast<std::size_t>(o.count));
  sim::Dataset d = sim::GenerateDataset(
      options, [&](std::size_t done, std::size_t) { progress.Update(done, "rows simulated"); });
  progress.Finish();
  std::ostringstream cmd;
  cmd << " regenerate: whirl dataset --count " << o.count << " --seed " << o.seed;
  if (o.window_s != sim::DatasetOptions{}.window_s) cmd << " --window-s " << o.window_s;
  if (o.no_disturbances) cmd << " --no-disturbances";
  cmd << " --out " << std::filesystem::path(o.out_path).filename().string();
  d.table.comments.insert(d.table.comments.begin(), cmd.str());
  sim::WriteDataset(d, o.out_path, o.curves_dir, cmd.str());
  int unsettled = 0;
  for (const auto& s : d.settle) unsettled += s.settled_before_tail ? 0 : 1;
  if (unsettled > 0)
    Warn(std::to_string(unsettled) +
         " rows did not settle before the tail window; use a longer "
         "--window-s");
  if (o.json) {
    PrintJson({{"schema", "whirl.dataset"},
               {"schema_version", 1},
               {"rows", d.table.inputs.size()},
               {"unsettled_rows", unsettled},
               {"seed", o.seed},
               {"window_s", o.window_s},
               {"disturbances", !o.no_disturbances},
               {"out", o.out_path},
               {"curves_dir", o.curves_dir}});
    return;
  }
  std::cout << "wrote " << d.table.inputs.size() << " rows to " << o.out_path;
  if (!o.curves_dir.empty()) std::cout << " and their curves to " << o.curves_dir;
  std::cout << "\n";
}

}  // namespace

void RegisterDataset(CLI::App& app) {
  auto opts = std::make_shared<DatasetCliOptions>();
  auto* sub = app.add_subcommand(
      "dataset",
      "Simulate a process table: a space-filling (Halton) design over the paper's ranges\n"
      "(hardness 60-65 HRC, diameter 50-100 mm, pitch 6-16 mm, raceway radius 3-10 mm, cutting\n"
      "speed 150-210 m/min), feasible screws only, each simulated on the reference blank and\n"
      "reduced to max_elongation_um (um) and settle_time_s (s). Disturbances ON unless\n"
      "--no-disturbances. Progress on stderr.");
  sub->add_option("--count", opts->count, "number of rows")
      ->check(NumberIn(1, 100000))
      ->capture_default_str();
  AddSeedOption(sub, &opts->seed, "seed of the design shift and of the disturbances")
      ->capture_default_str();
  sub->add_option("--out", opts->out_path, "output CSV (inputs, then targets), written atomically")
      ->required();
  sub->add_option("--curves-dir", opts->curves_dir,
                  "also write each row's curve (time_s, elongation_um) as row_NNNN.csv here, "
                  "with the table all-or-nothing (" +
                      std::string(kOutputDirRule) + ")");
  sub->add_option("--window-s", opts->window_s, "simulated time per row in s")
      ->check(PositiveNumber())
      ->capture_default_str();
  sub->add_option("--threads", opts->threads, "worker threads")
      ->check(NumberIn(1, 64))
      ->capture_default_str();
  sub->add_flag("--no-disturbances", opts->no_disturbances,
                "pure physics (no noise, no variation)");
  sub->add_flag("--json", opts->json,
                "machine output: JSON summary on stdout (rows, unsettled rows, files)");
  sub->callback([opts] { Run(*opts); });
}

}  // namespace whirl::cli
