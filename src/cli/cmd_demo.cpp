// whirl demo: the whole mission on the shipped defaults, in seconds: model (load or train),
// prediction for the reference screw and a new-type screw, arctangent curve, 840D plan files,
// comparison of every strategy (none, ramp, traditional, regression, model), report, summary.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <utility>

#include "cli/commands.h"
#include "cli/common.h"
#include "compare/compare.h"
#include "plan/load.h"
#include "plan/plan_document.h"
#include "compare/report.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/output_dir.h"
#include "interp/machine_profile.h"
#include "machine/scenarios.h"
#include "machine_eval/field_eval.h"  // step 7
#include "machine_report/machine_report.h"
#include "workpiece/model.h"
#include "screw/screw.h"

namespace whirl::cli {
namespace {

/// The machine profile the demo plans for (illustrative values).
constexpr const char* kDemoMachineProfile = "datasets/machines/example_840d.json";

struct DemoOptions {
  std::string out_dir = "whirl-demo-out";
  bool retrain = false;
  std::uint64_t seed = 1;
  bool no_plots = false;
  bool json = false;  ///< a JSON summary on stdout; the step lines go to stderr
};

// 7. The workpiece plan and the machine models a shop can train, on one machine of the field
// world's production scenario (cmd_machine.cpp: whirl machine evaluate); the report of its first
// test-day screw with the combined 840D programs of the network's plan and a shop-trainable
// machine model (the grey box of both_grey wherever it was fitted, else both_shop's sensor model;
// machine_report.h). Returns the summary of step 7 for --json.
nlohmann::json RunDemoMachineStep(const std::filesystem::path& out,
                                  const workpiece::WorkpieceModel& model, std::uint64_t seed,
                                  std::FILE* say) {
  machine_eval::FieldEvalOptions fo;
  fo.machines = 1;
  fo.seed = seed;
  fo.calendar.test_days = 1;
  fo.keep_report_screw = true;
  const machine_eval::SeedsEvaluation e = machine_eval::EvaluateFieldOverSeeds(
      machine::FindMachineScenario("production"), model,
      compare::BuildExperienceRule(ReadProcessTable(ProjectPath(kHistoryTable), true)),
      lead::ReadIsoToleranceTable(ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv")),
      fo, 1);
  const machine_eval::MachineEvaluation& run = e.runs.front();
  std::fprintf(say, "7. both halves on a drifting machine (whirl machine evaluate): %s\n%s",
               run.summary.message.c_str(), machine_eval::FormatSeedsTable(e, false).c_str());
  nlohmann::json j = {{"summary", run.summary.message}};
  if (!run.report) {
    Warn("step 7: no test-day screw was evaluated without error: no machine report");
    return j;
  }
  // The combined 840D programs of the report's screw, for the simulated machine's profile.
  const std::string dir = (out / "machine_report").string();  // replaces the earlier report
  const interp::MachineProfile profile =
      interp::LoadMachineProfile(ProjectPath("datasets/machines/whirling_840d.json"));
  const machine_report::MachineReport r =
      machine_report::WriteMachineScrewReport(dir, *run.report, &profile);
  if (!r.programs_note.empty()) Warn(r.programs_note);
  std::fprintf(say,
               "   report: %s\n   combined 840D programs of what a shop can train (the network's "
               "plan and %s;\n   the drift action owns SD43900-43920, the plan hands its K0, "
               "slope and\n   reference over): %s/WHIRL_DRIFT_COMP.SPF, WHIRL_TEMP_COMP.SPF, "
               "resets\n   machine model: %s\n",
               r.index_html.c_str(),
               r.programs_grey ? "the grey box of both_grey" : "both_shop's sensor model",
               dir.c_str(), r.programs_reason.c_str());
  j["report"] = r.index_html;
  j["programs_model"] = r.programs_grey ? "both_grey" : "both_shop";
  j["programs_reason"] = r.programs_reason;
  j["dir"] = dir;
  return j;
}

// The --json summary of one screw: prediction, plan files and each strategy's accumulated lead
// error within 1000 mm [um].
nlohmann::json DemoScrewJson(const compare::ScrewComparison& c, const std::filesystem::path& out,
                             const std::vector<std::string>& files) {
  nlohmann::json j = {{"name", c.screw.name},
                      {"predicted_max_elongation_um", c.prediction.mean.max_elongation_um},
                      {"predicted_max_elongation_std_um", c.prediction.stddev.max_elongation_um},
                      {"predicted_settle_time_s", c.prediction.mean.settle_time_s},
                      {"predicted_settle_time_std_s", c.prediction.stddev.settle_time_s},
                      {"outside_domain", c.prediction.outside_domain},
                      {"plan_segments", c.plan.segments.size()},
                      {"files", nlohmann::json::array()},
                      {"accumulated_1000_um", nlohmann::json::object()}};
  for (const auto& f : files) j["files"].push_back((out / f).string());
  for (compare::Strategy s : compare::kStrategies)
    j["accumulated_1000_um"][compare::ToString(s)] = c.Outcome(s).metrics.accumulated_1000_um;
  return j;
}

void RunDemo(const DemoOptions& o) {
  namespace fs = std::filesystem;
  const auto start = std::chrono::steady_clock::now();
  std::FILE* say = o.json ? stderr : stdout;  // stdout holds only the JSON with --json
  nlohmann::json summary = {{"schema", "whirl.demo"},
                            {"schema_version", 1},
                            {"out_dir", o.out_dir},
                            {"seed", o.seed},
                            {"screws", nlohmann::json::array()}};
  // The output directory's rule before anything runs; the plan files and the model are made in
  // its staging folder and committed together, the reports are output directories of their own.
  OutputDir files(o.out_dir, "--out-dir");
  const fs::path out = files.path();
  const fs::path stage = files.Staging();

  const std::string model_path = ProjectPath("models/default.json");
  const std::string train_path = ProjectPath(kHistoryTable);
  const ProcessTable history = ReadProcessTable(train_path, /*require_targets=*/true);
  workpiece::WorkpieceModel model;
  std::string model_source;
  if (!o.retrain && fs::exists(model_path)) {
    model = workpiece::LoadWorkpieceModel(model_path);
    model_source = model_path;
    std::fprintf(say, "1. model: loaded %s, %s (trained on %d samples of %s)\n",
                 model_path.c_str(), model.Describe().c_str(), model.training_samples,
                 model.training_data.c_str());
  } else {
    if (!o.retrain) Warn(model_path + " not found: training a model from " + train_path);
    model = workpiece::TrainWorkpieceModel(history, {}, train_path);
    model_source = "trained now from " + train_path;
    workpiece::SaveWorkpieceModel(stage / "model.json", model);
    files.AddStaged("model.json");
    std::fprintf(say, "1. model: trained on %zu rows of %s (%s), saved to %s\n",
                 history.inputs.size(), train_path.c_str(), model.Describe().c_str(),
                 (out / "model.json").string().c_str());
  }

  const std::string ref_path = ProjectPath("datasets/screws/reference_80x10x6000.json");
  const screw::Screw reference = screw::ReadScrew(ref_path);  // a missing shipped file is an error
  const screw::Screw new_type = compare::NewTypeScrew(reference);
  const auto& n = new_type.process;
  std::fprintf(say,
               "2. screws: %s (shipped), and %s defined in code: reference blank with hardness "
               "%.0f HRC, diameter %.0f mm, lead %.0f mm, raceway radius %.1f mm, cutting speed "
               "%.0f m/min (not a training row)\n",
               reference.name.c_str(), new_type.name.c_str(), n.hardness_hrc, n.diameter_mm,
               n.pitch_mm, n.raceway_radius_mm, n.cutting_speed_m_min);

  const compare::ExperienceRule rule = compare::BuildExperienceRule(history);
  const lead::IsoToleranceTable iso = lead::ReadIsoToleranceTable(
      ProjectPath("datasets/standards/iso3408_3_lead_tolerances.csv"));
  compare::CompareOptions co;
  co.seed = o.seed;
  co.band = true;  // the report's lead plots show the model's +-1 sd band
  // The example machine's facts (ID range, R parameters, offset): a real run names its own.
  const interp::MachineProfile profile =
      interp::LoadMachineProfile(ProjectPath(kDemoMachineProfile));
  profile.ApplyTo(co.plan);
  std::vector<compare::ScrewComparison> results;
  std::vector<plan::ControlLoad> control;  // the report's "load onto the control" box
  // The NC files' stems are their program names on the control (letters, digits, '_', at most
  // 24 characters: interp::CheckProgramName), so they cannot carry the screw's name.
  const std::pair<const screw::Screw*, std::string> screws[] = {{&reference, "WHIRL_REFERENCE"},
                                                              {&new_type, "WHIRL_NEW_TYPE"}};
  // Step 3 for every screw, then step 4 for every screw: the steps print in order.
  for (const auto& [screw, program] : screws) {
    compare::ScrewComparison c = compare::CompareScrew(*screw, model, rule, iso, co);
    const auto& p = c.prediction;
    std::fprintf(say,
                 "3. %s: predicted max elongation %.1f +- %.1f um, settle time %.0f +- %.0f s%s; "
                 "arctan curve k = %.2f, p = %.3f\n",
                 screw->name.c_str(), p.mean.max_elongation_um, p.stddev.max_elongation_um,
                 p.mean.settle_time_s, p.stddev.settle_time_s,
                 p.outside_domain ? " (outside the training domain)" : "",
                 c.predicted_curve.shape_k, c.predicted_curve.time_exponent);
    results.push_back(std::move(c));
  }
  for (std::size_t i = 0; i < results.size(); ++i) {
    const compare::ScrewComparison& c = results[i];
    const screw::Screw* screw = screws[i].first;
    const std::string& program = screws[i].second;
    const std::string slug = compare::Slug(screw->name);
    const std::string provenance = "whirl demo, model " + model_source;
    const nlohmann::json plan_json =
        plan::PlanDocument(c.plan, c.predicted_curve, c.screw, c.kinematics,
                              {model_source, c.prediction, c.prediction.mean}, provenance);
    const std::vector<std::string> names = {slug + "_plan.json", slug + "_plan.csv",
                                            program + ".SPF", program + "_RESET.SPF"};
    plan::WritePlanFiles(
        {stage / names[0], stage / names[1], stage / names[2], stage / names[3]}, plan_json, c.plan,
        provenance, "whirl demo: model " + model_source + ", screw " + screw->name);
    for (const auto& name : names) files.AddStaged(name);
    // The report lives in report/, the files one level up.
    control.push_back(plan::PlanFilesLoad("../", program, names[1], names[0], c.plan, &profile));
    summary["screws"].push_back(DemoScrewJson(c, out, names));
    std::fprintf(say,
                 "4. %s: 840D plan %zu segments (max |SD43910| %.2e <= MD32760 %.2g), written to "
                 "%s_plan.json/.csv and %s.SPF (reset: %s_RESET.SPF)\n",
                 screw->name.c_str(), c.plan.segments.size(), c.plan.max_abs_slope,
                 c.plan.options.md32760, (out / slug).string().c_str(), program.c_str(),
                 program.c_str());
  }

  files.Keep("report");
  files.Keep("machine_report");
  files.Commit();

  compare::ReportOptions ro;
  ro.plots = !o.no_plots;
  ro.control = control;
  ro.history = train_path + " (" + std::to_string(history.inputs.size()) + " past screws)";
  ro.provenance = {"command: whirl demo --out-dir " + o.out_dir + " --seed " +
                       std::to_string(o.seed) + (o.retrain ? " --retrain" : ""),
                   "model: " + model_source, "history (traditional rule): " + train_path};
  ro.notes = {
      "The new-type screw is defined in the demo: the reference blank "
      "with hardness 61 HRC, diameter 63 mm, lead 12 mm, raceway radius 4.0 mm, cutting "
      "speed 200 m/min, a combination that is not a training row."};
  const compare::ReportResult report = compare::WriteReport(out / "report", results, ro);
  for (const auto& w : report.warnings) Warn(w);

  std::fprintf(say, "5. comparison (truth: simulator with seeded disturbances, seed %llu):\n",
               static_cast<unsigned long long>(o.seed));
  for (const auto& c : results) {
    std::fprintf(say, "%s\n%s", c.screw.name.c_str(), compare::FormatComparisonTable(c).c_str());
  }
  std::fprintf(say, "6. report: %s (%s)\n", report.index_html.string().c_str(),
               report.plots_rendered ? "with plots" : "plots skipped");
  summary["machine"] =
      RunDemoMachineStep(out, model, o.seed, say);  // both halves on a drifting machine
  std::fprintf(say, "summary:");
  for (const auto& c : results) {
    const auto um = [&c](compare::Strategy s) { return c.Outcome(s).metrics.accumulated_1000_um; };
    const auto& r = c.model_vs_traditional;
    std::fprintf(
        say,
        " %s: accumulated lead error within 1000 mm %.1f um (model), %.1f um (regression), "
        "%.1f um (traditional), %.1f um (ramp), %.1f um (none); model %s traditional;",
        c.screw.name.c_str(), um(compare::Strategy::kModel), um(compare::Strategy::kRegression),
        um(compare::Strategy::kTraditional), um(compare::Strategy::kRamp),
        um(compare::Strategy::kNone),
        compare::ReductionWords(r.accumulated_1000_pct ? *r.accumulated_1000_pct : 0.0, 0)
            .c_str());
  }
  const double seconds =  // the whole run, step 7 (the drifting machine) included
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::fprintf(say, " done in %.1f s\n", seconds);
  if (!o.json) return;
  summary["model"] = model_source;
  summary["report"] = report.index_html.string();
  summary["plots_rendered"] = report.plots_rendered;
  PrintJson(summary);
}

}  // namespace

void RegisterDemo(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  auto* sub = app.add_subcommand(
      "demo",
      "Run the whole mission on the shipped defaults in seconds: load models/default.json (or\n"
      "train from datasets/whirling_500.csv, the shop history, if it is missing or with "
      "--retrain;\n"
      "the traditional rule learns from the same table), predict the\n"
      "elongation of the reference screw (datasets/screws/reference_80x10x6000.json) and of a\n"
      "new-type screw outside the training rows (reference blank; 61 HRC, 63 mm, lead 12 mm,\n"
      "raceway radius 4.0 mm, 200 m/min), build the arctangent curve, plan the 840D setting data\n"
      "(SD43900 mm, SD43910 -, SD43920 mm; files <screw>_plan.json/.csv and the NC programs\n"
      "WHIRL_REFERENCE.SPF, WHIRL_NEW_TYPE.SPF with their _RESET.SPF), cut both screws in the\n"
      "simulator once per strategy (none, ramp, traditional, regression, model: see 'whirl\n"
      "compare --help'), write the report (report/index.html: first the files to load onto the\n"
      "control, then the results) and print the lead errors (um) and reductions (%); then the\n"
      "same on a drifting machine (machine_report/index.html, see 'whirl machine evaluate').");
  sub->add_option("--out-dir", o->out_dir,
                  "output directory (default whirl-demo-out): " + std::string(kOutputDirRule) +
                      "; running the demo again replaces its files");
  sub->add_flag("--retrain", o->retrain,
                "train the model even if models/default.json exists, with `whirl train`'s\n"
                "default (per output the power law, a linear fit or a Gaussian process, chosen\n"
                "by cross-validated error; src/product/workpiece/model.h)");
  AddSeedOption(sub, &o->seed, "seed of the truth's disturbances (default 1)");
  sub->add_flag("--no-plots", o->no_plots, "skip gnuplot (report data and HTML only)");
  sub->add_flag("--json", o->json,
                "machine output: a JSON summary on stdout (predictions, plan files, accumulated "
                "lead error per strategy [um], reports); the step lines go to stderr");
  sub->callback([o] { RunDemo(*o); });
}

}  // namespace whirl::cli
