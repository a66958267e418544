#pragma once
// The manual of the lab's synthetic module: documented synthetic measurements for the product
// modules that have no public data to test on (this file: the ball bar, ballbar/; surface.h: the
// worktable, surface/).
//
// Documented simulated ball-bar measurements (no public measurements exist): a spindle warm-up
// read with three pivots, and circle traces with planted thermal errors. Deterministic for a seed
// on every platform (core/random.h). SIMULATED: every file written says so.
//
// Warm-up (the truth the drift command must recover):
//   drift_a(t) = D_a (1 - exp(-t / tau_a))  per MCS axis a, um, t in min from the spindle start;
//   D_X, D_Y uniform in +-[2, 10] um (sign drawn), D_Z uniform in [-60, -20] um (the spindle grows
//   towards the table), tau_a uniform in [40, 90] min; drawn from the seed.
//   Tool ball at ball_mm + drift(t) / 1000 (MCS). Pivots: the ideal layout for bar_length_mm
//   (trilateration.h: height L / sqrt(3), radius L sqrt(2/3), 120 degrees apart, B1 -> B2 along +X)
//   with each centre moved by up to +-5 mm in X and Y and +-1 mm in Z (seeded).
//   Bar temperature T(t) = bar_start_C + bar_rise_K (1 - exp(-t / bar_tau_min)), recorded to
//   0.01 K. A reading is |P - B_i| / (1 + alpha (T - 20 degC)) (the warm bar reads short, drift.h)
//   plus N(0, bar_noise_sd_um^2), rounded to resolution_um.
//   Blocks every interval_min from 0 to duration_min; in a block, `repeats` passes over the pivots
//   in palindromic order (1 2 3 3 2 1 ...), one reading every reading_step_min. Truth of block b:
//   drift(tbar_b) - drift(tbar_0), tbar the block's mean reading time.
// Circle traces: exact geometry (not the linear model of circle.h). Commanded point (u, v) =
// R (cos theta, sin theta) about the circle's centre; actual
//   u' = e1 + u (1 + s1) + alpha v + A1 sin(2 pi u / p1 + phi1)
//   v' = e2 + v (1 + s2) + A2 sin(2 pi v / p2 + phi2)
//   deviation = |(u', v')| - R + N(0, noise_sd_um^2)   (um)
// over a full circle (XY) or the upper semicircle (XZ, YZ: theta 0..180 degrees).
#include <Eigen/Core>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "ballbar/circle.h"
#include "ballbar/drift.h"

namespace whirl::synthetic {

struct WarmupOptions {
  std::uint64_t seed = 1;
  double duration_min = 240;       ///< warm-up length, min (60..720)
  double interval_min = 15;        ///< time between blocks, min (> block length + 2 min gap)
  int repeats = 2;                 ///< passes over the three pivots per block (1..10)
  double reading_step_min = 0.25;  ///< time between two readings in a block, min
  double bar_noise_sd_um = 0.1;    ///< noise of one reading, um
  double resolution_um = 0.1;      ///< bar resolution, um (readings rounded to it)
  double bar_alpha_per_K = 12e-6;  ///< true expansion coefficient of the bar, 1/K
  double bar_start_C = 20.5;       ///< bar temperature at t = 0, degC
  double bar_rise_K = 1.5;         ///< bar warming over the run, K
  double bar_tau_min = 90;         ///< its time constant, min
  double bar_length_mm = 150;      ///< bar length the pivot layout is made for, mm
  Eigen::Vector3d ball_mm{300, 200, 150};  ///< commanded tool-ball position, MCS, mm
  void Validate() const;
};

struct WarmupSimulation {
  ballbar::PivotCentres pivots_mm{};
  ballbar::Readings readings;
  Eigen::Vector3d final_drift_um;  ///< D per axis
  Eigen::Vector3d tau_min;         ///< tau per axis
  std::vector<double> block_time_min;
  std::vector<Eigen::Vector3d> truth_um;  ///< per block, relative to the cold block
};

WarmupSimulation SimulateWarmup(const WarmupOptions& options);
/// Drift of the warm-up model at time t (min), um, relative to t = 0.
Eigen::Vector3d WarmupDrift(const WarmupSimulation& sim, double t_min);

/// Planted errors of one circle trace (see the header comment).
struct CirclePlant {
  ballbar::Plane plane = ballbar::Plane::kXY;
  double radius_mm = 100;
  int samples = 1440;  ///< over the full circle (0.25 deg), or half + 1 over the semicircle
  double centre_1_um = 0, centre_2_um = 0;
  double scale_1_um_per_m = 0, scale_2_um_per_m = 0;  ///< s1, s2
  double squareness_urad = 0;                         ///< alpha
  double cyclic_1_um = 0, cyclic_period_1_mm = 10, cyclic_phase_1_deg = 0;
  double cyclic_2_um = 0, cyclic_period_2_mm = 10, cyclic_phase_2_deg = 0;
  double noise_sd_um = 0.1;
  std::uint64_t seed = 1;
};

ballbar::CircleTrace SimulateCircle(const CirclePlant& plant);

/// Writes the demo measurement into `dir` (created if missing): readings.csv, pivots.json,
/// truth_drift.csv, circle_xy_scale.csv, circle_xy_cyclic.csv, circle_xz_parallelism.csv and a
/// README.md giving the command, the seed and every planted value, all-or-nothing through
/// core/output_dir.h (`dir` must be new, empty or a whirl output, never a symbolic link).
/// Returns a JSON summary (files, truth).
nlohmann::json WriteSimulatedMeasurement(const std::filesystem::path& dir,
                                         const WarmupOptions& options);

}  // namespace whirl::synthetic
