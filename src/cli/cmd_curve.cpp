// whirl curve: the arctan elongation curve (src/product/fit/arctan_curve.h) from a model's prediction for a
// screw, or from given features, sampled as CSV time_s,elongation_um.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/common.h"
#include "core/csv.h"
#include "core/curve.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/output_dir.h"
#include "fit/arctan_curve.h"
#include "workpiece/model.h"
#include "screw/screw.h"

namespace whirl::cli {
namespace {

struct CurveOptions {
  CurveSourceArgs source;
  double duration_s = 0;
  double step_s = 1.0;
  std::string out_path;
  bool json = false;
};

void Run(const CurveOptions& o) {
  CheckOutputs({{"--model", o.source.model_path}, {"--screw", o.source.screw_path}},
               {{"--out", o.out_path}});
  const bool by_model = !o.source.model_path.empty() || !o.source.screw_path.empty();
  const bool by_features =
      !std::isnan(o.source.max_elongation_um) || !std::isnan(o.source.settle_time_s);
  if (by_model == by_features)
    throw InputError(
        "curve: give either --model M --screw S.json or --max-elongation-um L --settle-time-s T");
  Features features;
  Features stddev{NAN, NAN};
  double duration_s = o.duration_s;
  std::string source;
  if (by_model) {
    if (o.source.model_path.empty() || o.source.screw_path.empty())
      throw InputError("curve: --model and --screw go together (got only " +
                       std::string(o.source.model_path.empty() ? "--screw" : "--model") + ")");
    const screw::Screw screw = screw::ReadScrew(o.source.screw_path);
    const screw::Kinematics kin = screw::ComputeKinematics(screw);
    const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(o.source.model_path);
    const workpiece::Prediction pred = workpiece::Predict(model, screw.process);
    GuardTrainingDomain(pred.outside_domain, pred.outside_domain_fields, o.source.screw_path,
                        o.source.allow_extrapolation);
    features = pred.mean;
    stddev = pred.stddev;
    if (duration_s == 0) duration_s = kin.cutting_time_s;
    source = "model " + o.source.model_path + ", screw " + o.source.screw_path;
  } else {
    if (std::isnan(o.source.max_elongation_um) || std::isnan(o.source.settle_time_s))
      throw InputError("curve: --max-elongation-um and --settle-time-s go together");
    features = {o.source.max_elongation_um, o.source.settle_time_s};
    source = "given features";
  }
  CheckPlanFeatures(features,
                    by_features ? "--max-elongation-um/--settle-time-s" : "the prediction");
  const fit::ArctanCurve curve =
      fit::ArctanCurve::FromFeatures(features, o.source.shape_k, o.source.time_exponent);
  if (duration_s == 0) duration_s = 3.0 * curve.settle_time_s;
  const double samples = std::floor(duration_s / o.step_s) + 1;
  if (samples > 1e7)
    throw InputError("curve: " + FormatNumber(samples) + " samples (duration " +
                     FormatNumber(duration_s) + " s / step " + FormatNumber(o.step_s) +
                     " s): at most 1e7, raise --step-s");
  ElongationCurve c;
  for (std::size_t i = 0; i < static_cast<std::size_t>(samples); ++i) {
    const double t = o.step_s * static_cast<double>(i);
    c.time_s.push_back(t);
    c.elongation_um.push_back(curve.ElongationUm(t));
  }
  if (c.time_s.back() < duration_s) {
    c.time_s.push_back(duration_s);
    c.elongation_um.push_back(curve.ElongationUm(duration_s));
  }
  const std::vector<std::string> comments = {
      "whirl curve (" + source + ")",
      std::string(fit::kArctanFormula) + "; L = " + FormatNumber(curve.max_elongation_um) +
          " um, t_s = " + FormatNumber(curve.settle_time_s) +
          " s, k = " + FormatNumber(curve.shape_k) + ", p = " + FormatNumber(curve.time_exponent)};
  if (!o.out_path.empty()) WriteElongationCurve(o.out_path, c, comments);

  if (o.json) {
    nlohmann::json j = {{"schema", "whirl.curve"},  {"schema_version", 1},
                        {"source", source},         {"curve", curve},
                        {"duration_s", duration_s}, {"samples", c.size()}};
    if (by_model)
      j["prediction_stddev"] = {{"max_elongation_um", stddev.max_elongation_um},
                                {"settle_time_s", stddev.settle_time_s}};
    if (!o.out_path.empty()) j["out"] = o.out_path;
    PrintJson(j);
    return;
  }
  if (o.out_path.empty()) {
    std::vector<std::vector<double>> rows;
    for (std::size_t i = 0; i < c.size(); ++i) rows.push_back({c.time_s[i], c.elongation_um[i]});
    std::cout << FormatCsv({"time_s", "elongation_um"}, rows, comments);
    return;
  }
  std::printf("%s (%s)\n", curve.Describe().c_str(), source.c_str());
  if (by_model)
    std::printf("prediction std: %.3g um, %.3g s\n", stddev.max_elongation_um,
                stddev.settle_time_s);
  std::printf("written: %s (%zu samples over %.1f s)\n", o.out_path.c_str(), c.size(), duration_s);
}

}  // namespace

void RegisterCurve(CLI::App& app) {
  auto o = std::make_shared<CurveOptions>();
  auto* sub = app.add_subcommand(
      "curve",
      "The elongation curve of the unmachined section as the arctan model\n"
      "  l(t) = L atan(k (t/t_s)^p)/atan(k) for t < t_s, L after   [l in um, t in s]\n"
      "from a model's prediction for a screw (--model M --screw S.json; L and t_s are the\n"
      "predicted max elongation and settle time) or from given features\n"
      "(--max-elongation-um L --settle-time-s T). Writes CSV time_s,elongation_um (--out,\n"
      "atomically; else CSV on stdout). A screw outside the training domain is an error unless\n"
      "--allow-extrapolation.");
  AddCurveSourceOptions(sub, &o->source, false);
  sub->add_option("--duration-s", o->duration_s,
                  "sampled time span [s] (default: the screw's cutting time, else 3 t_s)")
      ->check(NonNegativeNumber());
  sub->add_option("--step-s", o->step_s, "sample spacing [s]")
      ->capture_default_str()
      ->check(PositiveNumber());
  sub->add_option("--out", o->out_path, "write the curve CSV here (atomically)");
  sub->add_flag("--json", o->json, "machine output: curve parameters as JSON on stdout");
  sub->callback([o] { Run(*o); });
}

}  // namespace whirl::cli
