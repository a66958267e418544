// whirl plan: compensation points and SINUMERIK 840D temperature-compensation setting data
// (interp/sinumerik.h) for a screw, from a model's prediction (or given features).
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/common.h"
#include "compare/plan_document.h"
#include "core/error.h"
#include "core/limits.h"
#include "fit/arctan_curve.h"
#include "interp/sinumerik.h"
#include "nn/model.h"
#include "sim/screw.h"

namespace whirl::cli {
namespace {

struct PlanCliOptions {
  std::string model_path;
  std::string screw_path;
  double max_elongation_um = NAN;
  double settle_time_s = NAN;
  double shape_k = fit::kDefaultShapeK;
  double time_exponent = fit::kDefaultTimeExponent;
  interp::PlanOptions plan;
  std::string sign = "subtract";
  std::string out_path;
  std::string csv_path;
  std::string nc_path;
  bool allow_extrapolation = false;
  bool json = false;
};

void Run(const PlanCliOptions& o) {
  const bool by_features = !std::isnan(o.max_elongation_um) || !std::isnan(o.settle_time_s);
  if (by_features == !o.model_path.empty())
    throw InputError("plan: give either --model M or --max-elongation L --settle-time T");
  interp::PlanOptions options = o.plan;
  options.sign = interp::ParseSignConvention(o.sign);
  options.Validate();
  const sim::Screw screw = sim::ReadScrew(o.screw_path);
  const sim::Kinematics kin = sim::ComputeKinematics(screw);

  compare::PlanSource plan_source;
  std::string source;
  if (!by_features) {
    const nn::Model model = nn::LoadModel(o.model_path);
    const nn::Prediction pred = nn::Predict(model, screw.process);
    GuardTrainingDomain(pred.outside_domain, pred.outside_domain_fields, o.screw_path,
                        o.allow_extrapolation);
    plan_source = {o.model_path, pred, pred.mean};
    source = "model " + o.model_path + ", screw " + o.screw_path;
  } else {
    if (std::isnan(o.max_elongation_um) || std::isnan(o.settle_time_s))
      throw InputError("plan: --max-elongation and --settle-time go together");
    plan_source.features = {o.max_elongation_um, o.settle_time_s};
    source = "given features, screw " + o.screw_path;
  }
  if (options.direction < 0 && options.sign == interp::SignConvention::kSubtract)
    Warn(
        "direction -1 with sign 'subtract': with the cut running towards the chuck the growth "
        "points along +axis, so 'add' is the consistent choice if the control adds dK to the "
        "setpoint (see 'whirl plan --help'); keeping 'subtract' as asked");

  CheckPlanFeatures(plan_source.features, by_features ? "--max-elongation/--settle-time"
                                                      : "prediction of " + o.model_path);
  const fit::ArctanCurve curve =
      fit::ArctanCurve::FromFeatures(plan_source.features, o.shape_k, o.time_exponent);
  const interp::CompensationPlan plan =
      interp::BuildPlan(curve, kin.axial_feed_mm_s, screw.thread_length_mm, options);
  const std::string provenance = "whirl plan (" + source + "), " + curve.Describe();
  const nlohmann::json j = compare::PlanDocument(plan, curve, screw, kin, plan_source, provenance);
  compare::WritePlanFiles({o.out_path, o.csv_path, o.nc_path}, j, plan, provenance,
                          curve.Describe() + " (" + source + ")");

  if (o.json) {
    PrintJson(j);
    return;
  }
  std::printf("%s\n", provenance.c_str());
  std::printf("axial feed %.4f mm/min, cutting time %.1f s over %.1f mm of thread\n",
              kin.axial_feed_mm_min, plan.cutting_time_s, plan.thread_length_mm);
  const std::string uniform = plan.uniform_point_count > 0
                                  ? std::to_string(plan.uniform_point_count)
                                  : std::string("more than 1000000");
  std::printf(
      "compensation points: %zu (%zu segments), uniform spacing needs %s for the same "
      "%.3g um bound\n",
      plan.point_count, plan.segments.size(), uniform.c_str(), options.tolerance_um);
  std::printf("largest |curve - compensation| on the check grid: %.4f um (tolerance %.4g um)\n",
              plan.max_deviation_um, options.tolerance_um);
  std::printf("largest |SD43910| %.3e (MD32760 cap %.3g), axis %s, sign %s, direction %+d\n",
              plan.max_abs_slope, options.md32760, options.axis.c_str(),
              interp::ToString(options.sign).c_str(), options.direction);
  for (const auto& [path, what] :
       {std::pair{o.out_path, "plan JSON"}, {o.csv_path, "PLC table"}, {o.nc_path, "NC program"}})
    if (!path.empty()) std::printf("written: %s (%s)\n", path.c_str(), what);
}

}  // namespace

void RegisterPlan(CLI::App& app) {
  auto o = std::make_shared<PlanCliOptions>();
  auto* sub = app.add_subcommand(
      "plan",
      "Plan SINUMERIK 840D temperature compensation of the thermal elongation for a screw:\n"
      "predict (max elongation, settle time) with --model (or give --max-elongation and\n"
      "--settle-time), build the arctan curve l(t) [um], choose the fewest breakpoints so the\n"
      "piecewise-linear compensation stays within --tolerance-um of the curve (dense while the\n"
      "curve moves, one flat segment on the plateau to the end of the thread), map time to axis\n"
      "position P(t) = machine offset + start + direction * feed * t [mm] with the screw's axial\n"
      "feed, and emit per segment A->B:\n"
      "  SD43900 $SA_TEMP_COMP_ABS_VALUE   = s l_A / 1000            [mm]\n"
      "  SD43910 $SA_TEMP_COMP_SLOPE       = s (l_B - l_A)/1000/(P_B - P_A) [-]\n"
      "  SD43920 $SA_TEMP_COMP_REF_POSITION = P_A                    [mm]\n"
      "with s = -1 (--sign subtract, default) or +1 (add). Default 'subtract': the cut runs\n"
      "towards the chuck, so the growth of the unmachined section points against the travel;\n"
      "with --direction +1 following it means dK = -l, assuming the control adds dK to the\n"
      "setpoint (the manual does not say plainly: verify once on the machine). A slope above\n"
      "MD32760 is an error. Outputs: plan JSON (--out, schema whirl.plan v1, the same document\n"
      "as 'whirl demo'), PLC table CSV (--csv), NC program with synchronized actions (--nc);\n"
      "all-or-nothing: if one cannot be written (missing directory, a directory, symlink, FIFO or\n"
      "device at the path) none is and previous files stay. Requires MD32750 = 3.");
  sub->add_option("--model", o->model_path, "model file written by 'whirl train'")
      ->check(CLI::ExistingFile);
  sub->add_option("--screw", o->screw_path,
                  "screw file (JSON): process inputs, thread length "
                  "and settings that give the axial feed")
      ->required()
      ->check(CLI::ExistingFile);
  sub->add_option("--max-elongation", o->max_elongation_um,
                  "instead of --model: plateau elongation L [um], 0..10000")
      ->check(CLI::NonNegativeNumber);
  sub->add_option("--settle-time", o->settle_time_s,
                  "instead of --model: settle time t_s [s], 1..1e6")
      ->check(CLI::PositiveNumber);
  AddCurveShapeOptions(sub, &o->shape_k, &o->time_exponent);
  sub->add_option("--tolerance-um", o->plan.tolerance_um,
                  "largest |compensation - curve| along the thread [um], >= 0.001 (1 nm)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sub->add_option("--axis", o->plan.axis, "axis name for $SA_TEMP_COMP_*[axis] and $AA_IM[axis]")
      ->capture_default_str();
  sub->add_option("--start-position-mm", o->plan.start_position_mm,
                  "axis position at the thread start (time 0), program coordinates [mm]")
      ->capture_default_str();
  sub->add_option("--direction", o->plan.direction,
                  "direction of travel along the axis while cutting: 1 or -1")
      ->capture_default_str()
      ->check(CLI::IsMember({1, -1}));
  sub->add_option("--machine-offset-mm", o->plan.machine_offset_mm,
                  "machine coordinate of the program zero on this axis [mm] (SD43920 and "
                  "$AA_IM are machine coordinates)")
      ->capture_default_str();
  sub->add_option("--sign", o->sign, "dK = -l (subtract) or +l (add), see above")
      ->capture_default_str()
      ->check(CLI::IsMember({"subtract", "add"}));
  sub->add_option("--md32760", o->plan.md32760,
                  "MD32760 $MA_COMP_ADD_VELO_FACTOR of the axis: cap on |SD43910| (0-0.10]")
      ->capture_default_str()
      ->check(CLI::Range(1e-12, interp::kMd32760Max));
  sub->add_option("--check-step-s", o->plan.check_step_s,
                  "largest step of the grid the tolerance is checked on [s] (refined as needed)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  sub->add_option("--out", o->out_path, "write the plan JSON here");
  sub->add_option("--csv", o->csv_path, "write the PLC table (CSV) here");
  sub->add_option("--nc", o->nc_path, "write the NC program (text, e.g. .mpf/.spf) here");
  sub->add_flag("--allow-extrapolation", o->allow_extrapolation,
                "plan even if the screw is outside the model's training domain");
  sub->add_flag("--json", o->json, "machine output: the plan JSON on stdout");
  sub->callback([o] { Run(*o); });
}

}  // namespace whirl::cli
