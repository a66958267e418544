#include "compare/curve_study.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/stats.h"
#include "sim/dataset.h"
#include "fit/features.h"
#include "sim/simulator.h"

namespace whirl::compare {
namespace {

ElongationCurve Head(const ElongationCurve& c, double t_max) {
  ElongationCurve h;
  for (std::size_t i = 0; i < c.size() && c.time_s[i] <= t_max; ++i) {
    h.time_s.push_back(c.time_s[i]);
    h.elongation_um.push_back(c.elongation_um[i]);
  }
  return h.size() >= 3 ? h : c;
}

}  // namespace

SimulatedFitReport FitSimulatedCurves(
    const SimulatedFitOptions& options,
    const std::function<void(std::size_t, std::size_t)>& progress) {
  if (options.count < 1)
    throw InputError("simulated fits: count = " + std::to_string(options.count) + ": must be >= 1");
  if (!(options.window_s > 0))
    throw InputError("simulated fits: window_s = " + std::to_string(options.window_s) +
                     ": must be > 0");
  if (!(options.fit_window_factor > 1))
    throw InputError("simulated fits: fit_window_factor = " +
                     std::to_string(options.fit_window_factor) + ": must be > 1");
  const sim::DatasetOptions defaults;
  SimulatedFitReport report;
  report.inputs = sim::DesignPoints(options.count, options.seed, defaults.ranges);
  std::vector<ElongationCurve> curves;
  std::vector<std::vector<fit::CurveFit>> fits;
  for (std::size_t i = 0; i < report.inputs.size(); ++i) {
    sim::SimOptions so = defaults.sim;
    so.duration_s = options.window_s;
    sim::DisturbanceOptions dist = sim::DatasetOptions::EnabledDisturbances();
    dist.enabled = options.disturbances;
    dist.seed = options.seed * 1000003ULL + i;
    const sim::SimulationResult r = sim::Simulate(sim::RowScrew(report.inputs[i]), so, dist);
    report.features.push_back(r.features);
    // The shape is calibrated over the window the features were extracted from (a few settle
    // times, fit/features.h step 0): beyond it the simulated curve keeps creeping up slowly.
    curves.push_back(Head(r.curve, fit::AnalyzeSettle(r.curve, so.settle).window_s));
    fits.push_back(fit::FitAllModels(
        Head(r.curve, options.fit_window_factor * r.features.settle_time_s), options.fit));
    if (progress) progress(i + 1, report.inputs.size());
  }
  report.shape = fit::CalibrateShape(curves, report.features, options.fit);
  double best_median = INFINITY;
  for (std::size_t m = 0; m < std::size(fit::kAllCurveModels); ++m) {
    ModelComparison mc;
    mc.model = fit::kAllCurveModels[m];
    std::vector<double> r2, rms;
    for (std::size_t i = 0; i < fits.size(); ++i) {
      r2.push_back(fits[i][m].r_squared);
      rms.push_back(fits[i][m].rms_residual_um);
      mc.converged_count += fits[i][m].summary.Converged() ? 1 : 0;
      bool best = true;
      for (std::size_t other = 0; other < fits[i].size(); ++other)
        if (fits[i][other].rms_residual_um < fits[i][m].rms_residual_um) best = false;
      mc.best_count += best ? 1 : 0;
    }
    mc.median_r_squared = Median(r2);
    mc.median_rms_residual_um = Median(rms);
    mc.worst_rms_residual_um = *std::max_element(rms.begin(), rms.end());
    if (mc.median_rms_residual_um < best_median) {
      best_median = mc.median_rms_residual_um;
      report.best_model = mc.model;
    }
    report.models.push_back(mc);
  }
  return report;
}

}  // namespace whirl::compare
