// whirl fit: features and fitted curve parameters of a measured (or simulated) elongation curve,
// and the model comparison / shape calibration over simulated curves (src/product/fit/curve_fit.h,
// src/lab/compare/curve_study.h).
#include <cstdio>
#include <memory>
#include <string>

#include "cli/commands.h"
#include "cli/common.h"
#include "compare/curve_study.h"
#include "core/curve.h"
#include "core/error.h"
#include "core/numbers.h"
#include "fit/curve_fit.h"
#include "fit/features.h"

namespace whirl::cli {
namespace {

struct FitOptions {
  std::string curve_path;
  int simulated = 0;
  std::uint64_t seed = 1;
  double window_s = 1800.0;
  bool disturbances = false;
  double max_gap_factor = 5.0;
  double fit_window_factor = 2.0;
  bool json = false;
};

nlohmann::json FitJson(const fit::CurveFit& f) {
  nlohmann::json params;
  for (std::size_t i = 0; i < f.parameter_names.size(); ++i)
    params[f.parameter_names[i]] = f.parameters[static_cast<Eigen::Index>(i)];
  return {{"model", fit::ToString(f.model)},
          {"parameters", params},
          {"r_squared", f.r_squared},
          {"rms_residual_um", f.rms_residual_um},
          {"max_abs_residual_um", f.max_abs_residual_um},
          {"samples", f.samples},
          {"converged", f.summary.Converged()},
          {"termination", fit::ToString(f.summary.termination)},
          {"lm", f.summary.BriefReport()}};
}

void RunCurve(const FitOptions& o) {
  ElongationCurve record = ReadElongationCurve(o.curve_path, o.max_gap_factor);
  // Time 0 is the start of the cut: the features count from the first sample (fit/features.h),
  // and so do the models (a logger's clock would shift their time axis).
  const double t0 = record.time_s.front();
  if (t0 != 0) {
    for (double& t : record.time_s) t -= t0;
    Warn(o.curve_path + ": time starts at " + MessageNumber(t0) +
         " s: the first sample is taken as the start of the cut (time 0)");
  }
  const fit::SettleAnalysis settle = fit::AnalyzeSettle(record);
  // The models describe the rise and the plateau it settles on; a long record's slow drift
  // (ambient, sensor) is not part of them, so they are fitted on [0, factor * t_s].
  ElongationCurve curve;
  const double t_max = o.fit_window_factor > 0 ? o.fit_window_factor * settle.features.settle_time_s
                                               : record.time_s.back();
  for (std::size_t i = 0; i < record.size() && record.time_s[i] <= t_max; ++i) {
    curve.time_s.push_back(record.time_s[i]);
    curve.elongation_um.push_back(record.elongation_um[i]);
  }
  if (curve.size() < 10) curve = record;
  const std::vector<fit::CurveFit> fits = fit::FitAllModels(curve);
  const fit::ShapeFit shape = fit::FitShape(curve, settle.features);
  std::size_t best = 0;
  for (std::size_t i = 1; i < fits.size(); ++i)
    if (fits[i].rms_residual_um < fits[best].rms_residual_um) best = i;
  for (const auto& f : fits)
    if (!f.summary.Converged())
      Warn(fit::ToString(f.model) + " fit did not converge: " + f.summary.BriefReport());
  if (!settle.settled_before_tail)
    Warn("the curve does not settle before its tail window: the settle time is unreliable (" +
         settle.message + "); log the elongation for at least twice the settle time (30 min "
         "from the start of the cut covers settle times up to 900 s)");

  if (o.json) {
    nlohmann::json models = nlohmann::json::array();
    for (const auto& f : fits) models.push_back(FitJson(f));
    PrintJson({{"schema", "whirl.fit"},
               {"schema_version", 2},
               {"curve", o.curve_path},
               {"samples", record.size()},
               {"fit_window_s", {curve.time_s.front(), curve.time_s.back()}},
               {"features",
                {{"max_elongation_um", settle.features.max_elongation_um},
                 {"settle_time_s", settle.features.settle_time_s},
                 {"settled_before_tail", settle.settled_before_tail},
                 {"noise_std_um", settle.noise_std_um},
                 {"criterion", settle.message}}},
               {"shape_with_features_fixed",
                {{"shape_k", shape.shape_k},
                 {"time_exponent", shape.time_exponent},
                 {"r_squared", shape.r_squared},
                 {"rms_residual_um", shape.rms_residual_um}}},
               {"models", models},
               {"best_model", fit::ToString(fits[best].model)},
               {"table_row",  // what goes into table.csv: the features, not a free fit's L, t_s
                {{"max_elongation_um", settle.features.max_elongation_um},
                 {"settle_time_s", settle.features.settle_time_s}}}});
    return;
  }
  std::printf("curve %s: %zu samples, %.6g to %.6g s; models fitted on %.6g to %.6g s\n",
              o.curve_path.c_str(), record.size(), t0 + record.time_s.front(),
              t0 + record.time_s.back(), curve.time_s.front(), curve.time_s.back());
  std::printf("features: max elongation %.4f um, settle time %.2f s (settle criterion of "
              "docs/methods.md; these two go into table.csv)\n",
              settle.features.max_elongation_um, settle.features.settle_time_s);
  std::printf(
      "arctan shape with these features fixed: k = %.4f, p = %.4f (R^2 %.6f, RMS %.4f um)\n",
      shape.shape_k, shape.time_exponent, shape.r_squared, shape.rms_residual_um);
  std::printf("%-9s %-84s %10s %12s\n", "model", "parameters (all free)", "R^2", "RMS [um]");
  for (const auto& f : fits) {
    std::string params;
    for (std::size_t i = 0; i < f.parameter_names.size(); ++i)
      params += (i ? " " : "") + f.parameter_names[i] + "=" +
                FormatSignificant(f.parameters[static_cast<Eigen::Index>(i)], 5);
    std::printf("%-9s %-84s %10.6f %12.4f%s\n", fit::ToString(f.model).c_str(), params.c_str(),
                f.r_squared, f.rms_residual_um, f.summary.Converged() ? "" : " (not converged)");
  }
  std::printf("best fit (smallest RMS residual): %s\n", fit::ToString(fits[best].model).c_str());
  // The row the user adds: the features above (the free fits' L and t_s only describe the shape).
  std::printf(
      "table.csv row (the screw's five inputs, then the features; the free fits' L and t_s are "
      "not table values):\n"
      "hardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,cutting_speed_m_min,"
      "max_elongation_um,settle_time_s\n"
      "<hrc>,<mm>,<mm>,<mm>,<m/min>,%.4f,%.2f\n",
      settle.features.max_elongation_um, settle.features.settle_time_s);
}

void RunSimulated(const FitOptions& o) {
  compare::SimulatedFitOptions so;
  so.count = o.simulated;
  so.seed = o.seed;
  so.window_s = o.window_s;
  so.disturbances = o.disturbances;
  Progress progress("simulating and fitting", static_cast<std::size_t>(o.simulated));
  const compare::SimulatedFitReport r =
      compare::FitSimulatedCurves(so, [&](std::size_t d, std::size_t) { progress.Update(d); });
  progress.Finish();
  if (o.json) {
    nlohmann::json models = nlohmann::json::array();
    for (const auto& m : r.models)
      models.push_back({{"model", fit::ToString(m.model)},
                        {"median_r_squared", m.median_r_squared},
                        {"median_rms_residual_um", m.median_rms_residual_um},
                        {"worst_rms_residual_um", m.worst_rms_residual_um},
                        {"best_count", m.best_count},
                        {"converged_count", m.converged_count}});
    nlohmann::json per_curve = nlohmann::json::array();
    for (const auto& f : r.shape.fits)
      per_curve.push_back({{"shape_k", f.shape_k}, {"time_exponent", f.time_exponent}});
    PrintJson(
        {{"schema", "whirl.fit_simulated"},
         {"schema_version", 2},
         {"curves", o.simulated},
         {"seed", o.seed},
         {"window_s", o.window_s},
         {"disturbances", o.disturbances},
         {"shape",
          {{"shape_k", r.shape.shape_k},
           {"time_exponent", r.shape.time_exponent},
           {"converged", r.shape.summary.Converged()},
           {"shape_k_range", {r.shape.min_shape_k, r.shape.max_shape_k}},
           {"time_exponent_range", {r.shape.min_time_exponent, r.shape.max_time_exponent}},
           {"median_r_squared", r.shape.median_r_squared},
           {"median_rms_residual_um", r.shape.median_rms_residual_um},
           {"plain_arctan",
            {{"shape_k", r.shape.plain_shape_k},
             {"time_exponent", 1.0},
             {"median_rms_residual_um", r.shape.plain_median_rms_residual_um}}},
           {"per_curve", per_curve},
           {"default_in_library",
            {{"shape_k", fit::kDefaultShapeK}, {"time_exponent", fit::kDefaultTimeExponent}}}}},
         {"models", models},
         {"best_model", fit::ToString(r.best_model)}});
    return;
  }
  std::printf("%d simulated curves (seed %llu, %.0f s each, disturbances %s)\n", o.simulated,
              static_cast<unsigned long long>(o.seed), o.window_s, o.disturbances ? "on" : "off");
  std::printf(
      "arctan shape with the simulator's features fixed, pooled fit: k = %.4f, p = %.4f%s\n"
      "  per curve: k %.4f to %.4f, p %.4f to %.4f; pooled shape on each curve: median R^2 "
      "%.6f, median RMS %.4f um\n"
      "  plain arctangent (p = 1), pooled: k = %.4f, median RMS %.4f um\n"
      "  built-in defaults (--shape-k, --time-exponent of plan, curve, compare): k = %.4f, "
      "p = %.4f\n",
      r.shape.shape_k, r.shape.time_exponent,
      r.shape.summary.Converged() ? "" : " (pooled fit not converged)", r.shape.min_shape_k,
      r.shape.max_shape_k, r.shape.min_time_exponent, r.shape.max_time_exponent,
      r.shape.median_r_squared, r.shape.median_rms_residual_um, r.shape.plain_shape_k,
      r.shape.plain_median_rms_residual_um, fit::kDefaultShapeK, fit::kDefaultTimeExponent);
  std::printf("%-9s %14s %20s %18s %6s %10s\n", "model", "median R^2", "median RMS [um]",
              "worst RMS [um]", "best", "converged");
  for (const auto& m : r.models)
    std::printf("%-9s %14.6f %20.4f %18.4f %6d %10d\n", fit::ToString(m.model).c_str(),
                m.median_r_squared, m.median_rms_residual_um, m.worst_rms_residual_um, m.best_count,
                m.converged_count);
  std::printf("best model (smallest median RMS residual): %s\n",
              fit::ToString(r.best_model).c_str());
}

}  // namespace

void RegisterFit(CLI::App& app) {
  auto o = std::make_shared<FitOptions>();
  auto* sub = app.add_subcommand(
      "fit",
      "Fit elongation-curve models to a measured or simulated curve and report its features.\n"
      "  --curve C.csv   columns time_s [s], elongation_um [um] ('#' comments allowed; gaps and\n"
      "                  non-increasing time are errors; log at least twice the settle time,\n"
      "                  e.g. 30 min from the start of the cut). Reports the features (max\n"
      "                  elongation [um], settle time [s]; criterion in docs/methods.md) and\n"
      "                  the table.csv row they make (these two, not a free fit's L and t_s),\n"
      "                  the arctan shape (k, p) with those features fixed, and three models\n"
      "                  with all parameters free:\n"
      "                    arctan   l = L atan(k (t/t_s)^p)/atan(k) up to t_s, L after\n"
      "                    parabola l = b t + (L - b t_s)(t/t_s)^2 up to t_s, L after\n"
      "                    sine     l = L sin(pi t/(2 t_s)) up to t_s, L after\n"
      "                  each with R^2 and RMS residual [um] (LM least squares). The arctan has\n"
      "                  one parameter more than the parabola (p); with p held at 1 it fitted\n"
      "                  best as well (docs/results.md).\n"
      "  --simulated N   simulate N curves over the paper's training ranges, fit (k, p) with the\n"
      "                  simulator's features fixed (the pooled fit over the N curves = how\n"
      "                  the defaults of --shape-k and --time-exponent are derived) and compare\n"
      "                  the three models (median R^2 / RMS, how often each is best).");
  auto* curve =
      sub->add_option("--curve", o->curve_path, "measured curve (CSV)")->check(CLI::ExistingFile);
  auto* simulated = sub->add_option("--simulated", o->simulated,
                                    "number of simulated curves to fit (model comparison and "
                                    "shape calibration)")
                        ->check(NumberIn(1, 1000));
  curve->excludes(simulated);
  AddSeedOption(sub, &o->seed, "seed of the design points and disturbances (--simulated)")
      ->capture_default_str();
  sub->add_option("--window-s", o->window_s, "simulated time per curve [s] (--simulated)")
      ->capture_default_str()
      ->check(PositiveNumber());
  sub->add_flag("--disturbances", o->disturbances,
                "add the simulator's disturbances: noise, drift, per-workpiece variation "
                "(--simulated)");
  sub->add_option("--max-gap-factor", o->max_gap_factor,
                  "a time step larger than this times the median step is a gap (error) [-]")
      ->capture_default_str()
      ->check(NumberIn(1.0, 1e6));
  sub->add_option("--fit-window-factor", o->fit_window_factor,
                  "fit the models on [0, factor * settle time] (the rise and its plateau, not a "
                  "long record's drift); 0 = the whole record [-]")
      ->capture_default_str()
      ->check(NonNegativeNumber());
  sub->add_flag("--json", o->json, "machine output: JSON on stdout");
  sub->callback([o] {
    if (o->curve_path.empty() && o->simulated == 0)
      throw InputError("fit: give --curve C.csv or --simulated N");
    if (!o->curve_path.empty())
      RunCurve(*o);
    else
      RunSimulated(*o);
  });
}

}  // namespace whirl::cli
