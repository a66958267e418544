// whirl predict: elongation features with standard deviations from a workpiece model
// (src/product/workpiece/model.h; the figures in src/product/workpiece/prediction_report.h).
#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/output_dir.h"
#include "core/process.h"
#include "workpiece/prediction_report.h"

namespace whirl::cli {
namespace {

struct PredictOptions {
  std::string model_path;
  std::string input_path;
  std::string out_path;
  bool json = false;
  // Single process: all five or none.
  double hardness_hrc = NAN;
  double diameter_mm = NAN;
  double pitch_mm = NAN;
  double raceway_radius_mm = NAN;
  double cutting_speed_m_min = NAN;
};

void Run(const PredictOptions& o) {
  CheckOutputs({{"--model", o.model_path}, {"--input", o.input_path}}, {{"--out", o.out_path}});
  const std::array<double, ProcessInputs::kCount> single = {
      o.hardness_hrc, o.diameter_mm, o.pitch_mm, o.raceway_radius_mm, o.cutting_speed_m_min};
  const std::array<const char*, ProcessInputs::kCount> flags = {"--hardness-hrc", "--diameter-mm",
                                                                "--pitch-mm", "--raceway-radius-mm",
                                                                "--cutting-speed-m-min"};
  std::string given, missing;
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    (std::isnan(single[i]) ? missing : given) += std::string(" ") + flags[i];

  ProcessTable table;
  if (!o.input_path.empty()) {
    if (!given.empty())
      throw InputError("predict: use either --input CSV or the five process flags, not both (got" +
                       given + ")");
    table = ReadProcessTable(o.input_path, /*require_targets=*/false);
  } else {
    if (!missing.empty())
      throw InputError(
          "predict: give --input CSV or all five of --hardness-hrc --diameter-mm --pitch-mm "
          "--raceway-radius-mm --cutting-speed-m-min (missing:" +
          missing + ")");
    table.source = "command line";
    table.inputs.push_back(ProcessInputs::FromArray(single));
    CheckProcessInputs(table.inputs.back(), "predict flags");
  }
  const workpiece::TablePrediction p =
      workpiece::PredictTable(workpiece::LoadWorkpieceModel(o.model_path), table);
  if (p.outside.rows > 0) {
    const std::string first =
        o.input_path.empty() ? std::string("the process")
                             : o.input_path + " line " +
                                   std::to_string(table.line_numbers[p.outside.first_row]);
    Warn(p.outside.Describe(static_cast<int>(p.predictions.size()), first) +
         " (the predictions extrapolate; their standard deviations may understate the error; "
         "--json lists the inputs of every row)");
  }
  if (!o.out_path.empty())
    workpiece::WritePredictionCsv(
        o.out_path, table, p,
        {"whirl predict --model " + o.model_path +
             (o.input_path.empty() ? "" : " --input " + o.input_path),
         "std = predictive standard deviation (noise + model uncertainty), "
         "outside_domain = 1 if an input is outside the training domain"});
  if (o.json)
    PrintJson(workpiece::PredictionJson(table, p, o.model_path));
  else
    std::cout << workpiece::FormatPredictionTable(table, p, o.input_path);
  if (!o.json && !o.out_path.empty()) std::cout << "written: " << o.out_path << "\n";
}

}  // namespace

void RegisterPredict(CLI::App& app) {
  auto o = std::make_shared<PredictOptions>();
  o->model_path = ProjectPath("models/default.json");
  auto* sub = app.add_subcommand(
      "predict",
      "Predict the two elongation features of hard whirling - maximum elongation of the\n"
      "unmachined section [um] and settle time [s] - each with a predictive standard deviation\n"
      "(noise plus model uncertainty: the network's Laplace approximation, or the chosen\n"
      "family's, calibrated by cross-validation; src/product/workpiece/model.h).\n"
      "Inputs outside the training domain get a warning on stderr and a flag in the output.\n"
      "Give either --input CSV (columns hardness_hrc, diameter_mm, pitch_mm,\n"
      "raceway_radius_mm, cutting_speed_m_min; if max_elongation_um and settle_time_s are\n"
      "present too they are used to report the prediction error) or all five process flags.\n" +
          ProcessLimitsHelp());
  sub->add_option("--model", o->model_path, "model file written by 'whirl train'")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  auto* input = sub->add_option("--input", o->input_path, "table of processes (CSV)")
                    ->check(CLI::ExistingFile);
  // Ranges: the physical limits (core/limits.h); the message names the table column as well.
  auto* h =
      sub->add_option("--hardness-hrc", o->hardness_hrc, "workpiece hardness [HRC], 20..70")
          ->check(NumberIn(Range{kMinHardnessHrc, kMaxHardnessHrc, false, "HRC", "hardness_hrc"}));
  auto* d = sub->add_option("--diameter-mm", o->diameter_mm, "screw diameter [mm], (0, 500]")
                ->check(NumberIn(Range{0, kMaxDiameterMm, true, "mm", "diameter_mm"}));
  auto* p = sub->add_option("--pitch-mm", o->pitch_mm, "lead (pitch) of the thread [mm], (0, 100]")
                ->check(NumberIn(Range{0, kMaxPitchMm, true, "mm", "pitch_mm"}));
  auto* r = sub->add_option("--raceway-radius-mm", o->raceway_radius_mm,
                            "raceway (ball-groove) radius [mm], (0, 50]")
                ->check(NumberIn(Range{0, kMaxRacewayRadiusMm, true, "mm", "raceway_radius_mm"}));
  auto* v =
      sub->add_option("--cutting-speed-m-min", o->cutting_speed_m_min,
                      "cutting speed of the whirling tools [m/min], (0, 1000]")
          ->check(NumberIn(Range{0, kMaxCuttingSpeedMMin, true, "m/min", "cutting_speed_m_min"}));
  for (auto* flag : {h, d, p, r, v}) input->excludes(flag);
  for (auto [flag, old] : {std::pair{h, "--hardness"},
                           {d, "--diameter"},
                           {p, "--pitch"},
                           {r, "--raceway-radius"},
                           {v, "--cutting-speed"}})
    AddDeprecatedAlias(sub, flag, old);
  sub->add_option("--out", o->out_path,
                  "write a CSV: the inputs, max_elongation_um, max_elongation_std_um,\n"
                  "settle_time_s, settle_time_std_s, outside_domain (0/1)");
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] { Run(*o); });
}

}  // namespace whirl::cli
