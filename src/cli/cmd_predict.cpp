// whirl predict: elongation features with Laplace standard deviations from a trained model
// (src/nn/model.h).
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
#include "nn/model.h"

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
  const nn::Model model = nn::LoadModel(o.model_path);
  const std::vector<nn::Prediction> pred = nn::PredictBatch(model, table.inputs);
  const bool have_targets = table.targets.size() == table.inputs.size() && !table.targets.empty();

  const nn::OutsideDomainSummary outside_summary = nn::SummarizeOutsideDomain(model, pred);
  const int outside = outside_summary.rows;
  if (outside > 0) {
    const std::string first =
        o.input_path.empty() ? std::string("the process")
                             : o.input_path + " line " +
                                   std::to_string(table.line_numbers[outside_summary.first_row]);
    Warn(outside_summary.Describe(static_cast<int>(pred.size()), first) +
         " (the predictions extrapolate; their standard deviations may understate the error; "
         "--json lists the inputs of every row)");
  }

  if (!o.out_path.empty()) {
    std::vector<std::string> header(kInputColumns.begin(), kInputColumns.end());
    for (const char* c : {"max_elongation_um", "max_elongation_std_um", "settle_time_s",
                          "settle_time_std_s", "outside_domain"})
      header.push_back(c);
    std::vector<std::vector<double>> rows;
    for (std::size_t q = 0; q < pred.size(); ++q) {
      const auto a = table.inputs[q].ToArray();
      std::vector<double> row(a.begin(), a.end());
      row.insert(row.end(), {pred[q].mean.max_elongation_um, pred[q].stddev.max_elongation_um,
                             pred[q].mean.settle_time_s, pred[q].stddev.settle_time_s,
                             pred[q].outside_domain ? 1.0 : 0.0});
      rows.push_back(std::move(row));
    }
    WriteFileAtomic(o.out_path,
                    FormatCsv(header, rows,
                              {"whirl predict --model " + o.model_path +
                                   (o.input_path.empty() ? "" : " --input " + o.input_path),
                               "std = Laplace predictive standard deviation (noise + weights), "
                               "outside_domain = 1 if an input is outside the training domain"}));
  }

  if (o.json) {
    nlohmann::json rows = nlohmann::json::array();
    double sq_e = 0, sq_t = 0;
    for (std::size_t q = 0; q < pred.size(); ++q) {
      nlohmann::json inputs;
      const auto a = table.inputs[q].ToArray();
      for (int i = 0; i < ProcessInputs::kCount; ++i) inputs[kInputColumns[i]] = a[i];
      nlohmann::json r = {{"inputs", inputs},
                          {"max_elongation_um", pred[q].mean.max_elongation_um},
                          {"max_elongation_std_um", pred[q].stddev.max_elongation_um},
                          {"settle_time_s", pred[q].mean.settle_time_s},
                          {"settle_time_std_s", pred[q].stddev.settle_time_s},
                          {"outside_domain", pred[q].outside_domain},
                          {"outside_domain_fields", pred[q].outside_domain_fields}};
      if (have_targets) {
        const double de = pred[q].mean.max_elongation_um - table.targets[q].max_elongation_um;
        const double dt = pred[q].mean.settle_time_s - table.targets[q].settle_time_s;
        r["error"] = {{"max_elongation_um", de}, {"settle_time_s", dt}};
        sq_e += de * de;
        sq_t += dt * dt;
      }
      rows.push_back(r);
    }
    nlohmann::json j = {
        {"model", o.model_path}, {"predictions", rows}, {"outside_domain_count", outside}};
    if (have_targets) {
      const double n = static_cast<double>(pred.size());
      j["rms_error"] = {{"max_elongation_um", std::sqrt(sq_e / n)},
                        {"settle_time_s", std::sqrt(sq_t / n)}};
    }
    PrintJson(j);
    return;
  }

  std::printf("%4s %8s %8s %7s %8s %9s | %22s | %18s | %s\n", "row", "HRC", "D [mm]", "P [mm]",
              "R [mm]", "v [m/min]", "max elongation [um]", "settle time [s]", "domain");
  double ape_e = 0, ape_t = 0;
  int n_e = 0, n_t = 0;  // a zero target has no percentage error: left out, never a division by 0
  for (std::size_t q = 0; q < pred.size(); ++q) {
    const auto& in = table.inputs[q];
    const auto& p = pred[q];
    std::printf("%4zu %8.4g %8.4g %7.4g %8.4g %9.4g | %10.5g +- %-8.3g | %8.5g +- %-6.3g | %s\n",
                q + 1, in.hardness_hrc, in.diameter_mm, in.pitch_mm, in.raceway_radius_mm,
                in.cutting_speed_m_min, p.mean.max_elongation_um, p.stddev.max_elongation_um,
                p.mean.settle_time_s, p.stddev.settle_time_s, p.outside_domain ? "OUTSIDE" : "in");
    if (have_targets) {
      const Features& t = table.targets[q];
      if (t.max_elongation_um > 0) {
        ape_e += std::abs(p.mean.max_elongation_um - t.max_elongation_um) / t.max_elongation_um;
        ++n_e;
      }
      if (t.settle_time_s > 0) {
        ape_t += std::abs(p.mean.settle_time_s - t.settle_time_s) / t.settle_time_s;
        ++n_t;
      }
    }
  }
  std::printf("(+- one predictive standard deviation, Laplace approximation)\n");
  if (have_targets) {
    std::printf(
        "targets in %s: mean absolute error %.3g %% (max elongation, %d rows with a target > 0), "
        "%.3g %% (settle time, %d rows)\n",
        o.input_path.c_str(), n_e > 0 ? 100 * ape_e / n_e : 0.0, n_e,
        n_t > 0 ? 100 * ape_t / n_t : 0.0, n_t);
  }
  if (!o.out_path.empty()) std::printf("written: %s\n", o.out_path.c_str());
}

}  // namespace

void RegisterPredict(CLI::App& app) {
  auto o = std::make_shared<PredictOptions>();
  o->model_path = ProjectPath("models/default.json");
  auto* sub = app.add_subcommand(
      "predict",
      "Predict the two elongation features of hard whirling - maximum elongation of the\n"
      "unmachined section [um] and settle time [s] - each with a standard deviation from the\n"
      "Laplace approximation of the Bayesian network (noise plus weight uncertainty).\n"
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
