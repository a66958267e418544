#pragma once
// The two features of an elongation curve (paper Fig. 2): maximum (plateau) elongation and settle
// time, from any curve, simulated or measured (CSV time_s,elongation_um).
//
// Settle criterion (documented, robust to sensor noise and slow drift):
//  1. Smooth: centred moving average over `smoothing_window_s` (noise std shrinks by
//  sqrt(samples)).
//  2. Plateau: least-squares LINE p(t) = b0 + b1 t through the RAW samples of the tail window (the
//     last `tail_fraction` of the record). A line, not a constant, so a slow drift (ambient,
//     sensor) does not bias the level; least squares over hundreds of samples averages the noise
//     out.
//  3. Noise: sigma = 1.4826 * MAD of the raw tail residuals about p(t) (robust std estimate).
//  4. Band: half-width b = max(tolerance_rel * |p(t)|, noise_sigma_multiplier * sigma /
//  sqrt(n_win))
//     where n_win is the number of samples in the smoothing window (so noise cannot keep the
//     smoothed curve outside a band narrower than its own scatter).
//  5. Settle time = the first sample time after which the smoothed curve stays within p(t) +- b for
//     the rest of the record. Max elongation = p(settle time): the plateau level where it is
//     reached.
// The record must extend well beyond the settle time (the tail must be plateau): use at least
// ~3x the expected settle time. The paper's reading ("essentially constant from ~250 s") matches
// tolerance_rel = 0.02.
#include <string>

#include "core/curve.h"
#include "core/process.h"

namespace whirl::sim {

struct SettleOptions {
  double tolerance_rel = 0.02;       ///< band half-width relative to the plateau, -
  double smoothing_window_s = 60.0;  ///< centred moving-average window, s
  double tail_fraction = 0.35;       ///< part of the record (by time) used for the plateau line, -
  double noise_sigma_multiplier = 3.0;  ///< band floor in smoothed-noise standard deviations, -
  /// Degree of the tail polynomial p(t): 1 (default, a line: follows a slow drift); 0 = constant
  /// plateau; 2 follows a curving drift but extrapolates noise back to the settle region badly
  /// (tested: settle times of noisy table rows scatter by > 100 %).
  int tail_degree = 1;
};

/// Full result of the settle analysis.
struct SettleAnalysis {
  Features features;
  double plateau_slope_um_per_s = 0;  ///< mean slope of p(t) over the tail, um/s (drift)
  double noise_std_um = 0;            ///< robust std of the raw tail residuals, um
  double band_um = 0;                 ///< band half-width used, um
  /// False when the smoothed curve never enters the band before the tail window starts (the record
  /// is too short to show a plateau); the settle time is then still reported but unreliable.
  bool settled_before_tail = false;
  std::string message;  ///< the numbers compared, for reports
};

/// InputError if the curve has fewer than 10 samples, non-increasing time, or non-finite values.
SettleAnalysis AnalyzeSettle(const ElongationCurve& curve, const SettleOptions& options = {});
Features ExtractFeatures(const ElongationCurve& curve, const SettleOptions& options = {});

}  // namespace whirl::sim
