// whirl compare: the lead error of one screw cut in the simulator without compensation, with the
// history baselines (ramp, traditional, regression), and with the model-based 840D plan; report.
#include <cstdio>
#include <iostream>
#include <memory>

#include "cli/commands.h"
#include "cli/common.h"
#include "compare/compare.h"
#include "compare/report.h"
#include "core/output_dir.h"
#include "core/process.h"
#include "workpiece/model.h"
#include "screw/screw.h"

namespace whirl::cli {
namespace {

struct CompareCliOptions {
  std::string model_path;
  std::string screw_path;
  std::uint64_t seed = 1;
  bool json = false;
  std::string report_dir;
  bool no_plots = false;
  bool no_disturbances = false;
  std::string history;
  std::string iso_table = ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv");
  double tolerance_um = interp::PlanOptions{}.tolerance_um;
  double md32760 = interp::kMd32760Default;
  double shape_k = fit::kDefaultShapeK;
  double time_exponent = fit::kDefaultTimeExponent;
};

void RunCompare(const CompareCliOptions& o, const std::string& command_line) {
  CheckOutputs({{"--model", o.model_path},
                {"--screw", o.screw_path},
                {"--history", o.history},
                {"--iso-table", o.iso_table}},
               {}, {{"--out-dir", o.report_dir}});
  const workpiece::WorkpieceModel model = workpiece::LoadWorkpieceModel(o.model_path);
  const screw::Screw screw = screw::ReadScrew(o.screw_path);
  const ProcessTable past = ReadProcessTable(o.history, /*require_targets=*/true);
  const compare::ExperienceRule rule = compare::BuildExperienceRule(past);
  // Said on stdout (stderr under --json) and on the page: the baselines are only as good as
  // the screws they come from.
  const std::string history =
      o.history + " (" + std::to_string(past.inputs.size()) + " past screws)";
  std::fprintf(o.json ? stderr : stdout, "history rules from: %s\n", history.c_str());
  const lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(o.iso_table);
  compare::CompareOptions co;
  co.seed = o.seed;
  co.disturbances_on = !o.no_disturbances;
  co.plan.tolerance_um = o.tolerance_um;
  co.plan.md32760 = o.md32760;
  co.shape_k = o.shape_k;
  co.time_exponent = o.time_exponent;
  co.band = !o.report_dir.empty();  // the report's lead plots show the model's +-1 sd band
  const compare::ScrewComparison c = compare::CompareScrew(screw, model, rule, iso, co);
  if (c.prediction.outside_domain)
    Warn("screw '" + screw.name + "' lies outside the model's training domain (" +
         JoinFields(c.prediction.outside_domain_fields) + "): the prediction extrapolates");
  if (!o.report_dir.empty()) {
    compare::ReportOptions ro;
    ro.plots = !o.no_plots;
    ro.history = history;
    ro.provenance = {"command: " + command_line, "model: " + o.model_path, "screw: " + o.screw_path,
                     "history (traditional rule): " + o.history,
                     "truth seed: " + std::to_string(o.seed)};
    const compare::ReportResult r = compare::WriteReport(o.report_dir, {c}, ro);
    for (const auto& w : r.warnings) Warn(w);
    std::cerr << "report: " << r.index_html.string() << std::endl;
  }
  if (o.json) {
    PrintJson(c);
    return;
  }
  std::printf("screw %s: thread %.0f mm, feed %.1f mm/min, cutting time %.1f min\n",
              screw.name.c_str(), screw.thread_length_mm, c.kinematics.axial_feed_mm_min,
              c.kinematics.cutting_time_s / 60);
  std::printf("truth (seed %llu, disturbances %s): max elongation %.1f um, settle %.0f s\n",
              static_cast<unsigned long long>(c.seed), c.disturbances_on ? "on" : "off",
              c.truth_features.max_elongation_um, c.truth_features.settle_time_s);
  std::printf(
      "model prediction: max elongation %.1f +- %.1f um, settle %.0f +- %.0f s; "
      "840D plan: %zu segments\n",
      c.prediction.mean.max_elongation_um, c.prediction.stddev.max_elongation_um,
      c.prediction.mean.settle_time_s, c.prediction.stddev.settle_time_s, c.plan.segments.size());
  std::printf("ramp rule: %.1f um (class %.0f mm, %d past screws) ramped in over %.0f s\n",
              c.experience_class.plateau_um, c.experience_class.nominal_diameter_mm,
              c.experience_class.screws, c.experience_ramp_time_s);
  std::printf(
      "traditional (%s, the strongest history rule): %.1f um, %.0f s; regression (log-linear): "
      "%.1f um, %.0f s\n",
      compare::ToString(c.traditional_rule).c_str(), c.traditional_features.max_elongation_um,
      c.traditional_features.settle_time_s,
      c.regression_features.max_elongation_um, c.regression_features.settle_time_s);
  std::printf("%s", compare::FormatComparisonTable(c).c_str());
}

}  // namespace

void RegisterCompare(CLI::App& app) {
  auto o = std::make_shared<CompareCliOptions>();
  auto* sub = app.add_subcommand(
      "compare",
      "Cut a screw in the simulator once per strategy and compare the lead error: none (no\n"
      "compensation); ramp (the old rule: the class's mean plateau of the past screws in\n"
      "--history ramped in linearly over their mean settle time); class, table, nearest (the\n"
      "shop's history rules: the diameter class's mean curve, a table keyed on ball size, speed\n"
      "and lead, the 3 nearest past screws); traditional (the strongest of those three, chosen\n"
      "by leave-one-out on --history); regression (log-linear least squares of both features on\n"
      "the five inputs of --history); model (the workpiece model's prediction). Every strategy\n"
      "but none and ramp goes through the same 840D plan (curve -> SD43900/SD43910/SD43920).\n"
      "The truth is the whole-thread simulation with seeded disturbances (--seed) the model\n"
      "never saw. Prints, in um, the accumulated lead error within any 1000 mm and over the\n"
      "thread, e_a, v_u, v_300, v_2pi, the ISO 3408-3 class reached and the reductions of the\n"
      "model against each strategy (100 (1 - model/baseline) %).");
  sub->add_option("--model", o->model_path, "model file (JSON, e.g. models/default.json)")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--screw", o->screw_path,
                  "screw file (JSON, e.g. datasets/screws/reference_80x10x6000.json)")
      ->required()
      ->check(CLI::ExistingFile);
  AddSeedOption(sub, &o->seed, "seed of the truth's disturbances (default 1)");
  sub->add_flag("--no-disturbances", o->no_disturbances,
                "simulate the truth without disturbances (the model's own world)");
  auto* report = sub->add_option(
      "--out-dir", o->report_dir,
      "write the HTML report (index.html, PNG plots, CSV data, report.json) into this directory: " +
          std::string(kOutputDirRule));
  AddDeprecatedAlias(sub, report, "--report");
  sub->add_flag("--no-plots", o->no_plots, "with --out-dir: skip gnuplot (data and HTML only)");
  // Required: a default would grade the user's model against screws the shop never cut.
  sub->add_option("--history", o->history,
                  "past screws of the history rules (ramp, class, table, nearest, traditional, "
                  "regression): a process table with targets, normally the table.csv your model "
                  "was trained on (the shipped model's: " +
                      std::string(kHistoryTable) + ")")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--iso-table", o->iso_table, "ISO 3408-3 tolerance table CSV (default: shipped)")
      ->check(CLI::ExistingFile);
  AddToleranceOption(sub, &o->tolerance_um);
  sub->add_option("--md32760", o->md32760,
                  "MD32760 $MA_COMP_ADD_VELO_FACTOR: cap on |SD43910|, - (default 0.01, max 0.10)")
      ->check(Md32760Number());
  AddCurveShapeOptions(sub, &o->shape_k, &o->time_exponent);
  sub->add_flag("--json", o->json, "machine output: the comparison as JSON on stdout");
  sub->callback([o, sub] {
    std::string cmd = "whirl compare";
    for (const auto& opt : sub->get_options())
      if (opt->count() > 0 && opt->get_name() != "--help") {
        cmd += " " + opt->get_name();
        if (opt->get_type_size() != 0) cmd += " " + opt->as<std::string>();
      }
    RunCompare(*o, cmd);
  });
}

}  // namespace whirl::cli
