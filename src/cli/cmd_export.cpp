// whirl export: a trained model as a TorchScript module for the PyTorch world.
// Compiled into build/whirl-torch only (the one whirl executable that links LibTorch);
// build/whirl forwards "whirl export ..." to it (cli/torch_forward.cpp).
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/error.h"
#include "core/numbers.h"
#include "core/output_dir.h"
#include "nn/model.h"
#include "workpiece/model.h"
#include "torch/crosscheck.h"

namespace whirl::cli {
namespace {

struct ExportCliOptions {
  std::string model_path;
  std::string torchscript_path;
  bool json = false;
};

void RunExport(const ExportCliOptions& o) {
  CheckOutputs({{"--model", o.model_path}}, {{"--torchscript", o.torchscript_path}});
  const nn::Model model = workpiece::LoadNetworkModel(o.model_path, "export");
  torch::ExportOptions options;
  options.description = "whirl elongation-feature model exported by 'whirl export --model " +
                        o.model_path + "' (" + torch::TorchVersion() +
                        "); training data: " + model.training_data +
                        "; forward(x[B,5] original units) -> [B,2] original units";
  const torch::ExportReport report = torch::ExportTorchScript(model, o.torchscript_path, options);
  if (o.json) {
    nlohmann::json j = report;
    j["model"] = o.model_path;
    PrintJson(j);
  } else if (report.written) {
    std::printf(
        "wrote %s (TorchScript, float64): forward(x) takes x[B, 5] = (%s) in original units and\n"
        "returns [B, 2] = (%s); reloaded and compared with the Eigen model on %d points of the\n"
        "training domain: max relative difference %.3g (tolerance %.3g)\n",
        report.path.c_str(),
        (report.input_names.at(0) + ", " + report.input_names.at(1) + ", " +
         report.input_names.at(2) + ", " + report.input_names.at(3) + ", " +
         report.input_names.at(4))
            .c_str(),
        (report.target_names.at(0) + ", " + report.target_names.at(1)).c_str(), report.check_points,
        report.max_relative_difference, report.tolerance);
  }
  if (!report.written) {
    throw CommandFailure("the reloaded TorchScript differs from the Eigen model by " +
                             FormatSignificant(report.max_relative_difference, 3) +
                             " relative (tolerance " + FormatSignificant(report.tolerance, 3) +
                             "); nothing written",
                         2);
  }
}

}  // namespace

void RegisterExport(CLI::App& app) {
  auto o = std::make_shared<ExportCliOptions>();
  auto* sub = app.add_subcommand(
      "export",
      "Export a trained model as a TorchScript module (load it with torch.jit.load in Python or\n"
      "torch::jit::load in C++). forward(x) takes x of shape [B, 5] (or [5]) in ORIGINAL units,\n"
      "columns hardness_hrc [HRC], diameter_mm [mm], pitch_mm [mm], raceway_radius_mm [mm],\n"
      "cutting_speed_m_min [m/min], and returns [B, 2] (or [2]) in original units:\n"
      "max_elongation_um [um], settle_time_s [s]. The mapminmax scaling is inside the module;\n"
      "weights are float64 parameters, input_names()/target_names()/description() tell the rest.\n"
      "The file is written atomically and only after reloading it and comparing its predictions\n"
      "with the Eigen model on the training-domain corners and centre (1e-12 relative).\n"
      "Only the mean is exported (no Laplace standard deviation). Exit code 2 if the check fails.");
  sub->add_option("--model", o->model_path, "Model file (JSON, written by 'whirl train')")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--torchscript", o->torchscript_path, "Output TorchScript file (e.g. model.pt)")
      ->required();
  sub->add_flag("--json", o->json, "Machine output: the export report as JSON on stdout");
  sub->callback([o] { RunExport(*o); });
}

}  // namespace whirl::cli
