#pragma once
// Fits over simulated curves of the training domain (src/lab/sim): derives the default shape k and
// time exponent p of the arctan curve (kDefaultShapeK, kDefaultTimeExponent) and repeats the
// paper's model comparison (arctan vs parabola vs sine, Li, Ma and Jiang section 3) on them. Driven
// by `whirl fit --simulated N`.
//
// For each design point (sim::DesignPoints: space-filling over the paper's ranges) the reference
// blank is simulated for window_s, features are extracted by sim::ExtractFeatures, and
//   * the shape (k, p) is fitted with L and t_s fixed to those features, per curve (FitShape)
//     and pooled over all curves (CalibrateShape), so that
//     ArctanCurve::FromFeatures(features, k, p) reproduces the simulator best;
//   * each model is fitted with all its parameters free (FitCurveModel) on the part of the record
//     up to fit_window_factor * t_s (the dynamic part and enough plateau to anchor it).
#include <cstdint>
#include <functional>
#include <vector>

#include "core/process.h"
#include "fit/curve_fit.h"

namespace whirl::compare {

struct SimulatedFitOptions {
  int count = 25;             ///< simulated curves (design points), >= 1
  std::uint64_t seed = 1;     ///< design shift and disturbance seeds
  double window_s = 1800.0;   ///< simulated time per curve, s (see sim::DatasetOptions::window_s)
  bool disturbances = false;  ///< add the simulator's disturbances (noise, drift, variation)
  /// Fit window for the free model fits: [0, fit_window_factor * t_s], clamped to the record.
  double fit_window_factor = 2.0;
  fit::CurveFitOptions fit;
};

struct ModelComparison {
  fit::CurveModel model = fit::CurveModel::kArctan;
  double median_r_squared = 0;
  double median_rms_residual_um = 0;
  double worst_rms_residual_um = 0;
  int best_count = 0;  ///< curves on which this model had the smallest RMS residual
  int converged_count = 0;
};

struct SimulatedFitReport {
  std::vector<ProcessInputs> inputs;                      ///< the design points
  std::vector<Features> features;                         ///< sim::ExtractFeatures of each curve
  fit::ShapeCalibration shape;                            ///< (k, p) with L, t_s fixed
  std::vector<ModelComparison> models;                    ///< in kAllCurveModels order
  fit::CurveModel best_model = fit::CurveModel::kArctan;  ///< smallest median RMS residual
};

/// Runs the simulations and fits. `progress(done, total)` after each curve. InputError for
/// count < 1, window_s <= 0, fit_window_factor <= 1.
SimulatedFitReport FitSimulatedCurves(
    const SimulatedFitOptions& options,
    const std::function<void(std::size_t, std::size_t)>& progress = {});

}  // namespace whirl::compare
