#pragma once
// Transient axial heat conduction in the screw blank during hard whirling and the resulting
// thermal elongation of the unmachined section (Li, Ma and Jiang's process; docs/simulator.md).
//
// Model (1D in the section-mean temperature rise theta(x, t) = T - T_ref, x from the chuck face):
//   rho c A d(theta)/dt = k A d2(theta)/dx2 - h P (theta - theta_amb(t)) + q(t) s(x - x_c(t))
//   * A = pi D^2 / 4, P = pi D (groove neglected in A and P: < 2 % of A for the paper's range).
//   * Integrating the 3D equation over the cross section gives exactly this equation for the
//     section mean, except that the loss uses the surface temperature; Biot = h R / k ~ 0.03 makes
//     the difference O(Bi) (PhysicsConstants::heat_transfer_coefficient_w_m2_k).
//   * Heat source: q = heat_to_workpiece_w (HeatInput) spread uniformly over the contact width w
//     (groove width) centred on the cut point x_c(t) = Kinematics::CutPositionMm(t), which moves
//     towards the chuck at v_f. Each step deposits the EXACT time average over the step of the
//     moving box's overlap with every cell (closed form), so the source moves continuously: no
//     sawtooth from jumping between cells. The heat stops when the cut reaches the thread end.
//   * Boundaries: chuck face (x = 0) held at the ambient temperature (massive chuck and spindle:
//     assumption); free end (x = length) loses heat through its end face with the same h.
//   * Initial state: blank at the ambient temperature T_ref
//   (ProcessSettings::ambient_temperature_c).
//     Elongation is measured against T_ref: the finished screw is measured after cooling back to
//     it.
//   * Elongation of the unmachined section at the cut point (Li, Ma and Jiang):
//       dL(t) = alpha * integral_0^{x_c(t)} theta(x, t) dx,  reported in um; positive = growth of
//       the unmachined section, which moves the cut point away from the chuck (towards the free
//       end).
// Numerics: finite volumes on a uniform grid over the whole blank, BDF2 in time (first step
// implicit Euler): A-stable, second order, unconditionally stable. The matrix is constant, so its
// tridiagonal LU (Thomas) factors are computed once; each step costs O(cells). The elongation
// integral uses the piecewise-linear reconstruction between cell centres up to x_c.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/curve.h"
#include "core/process.h"
#include "fit/features.h"
#include "sim/physics.h"
#include "screw/screw.h"

namespace whirl::sim {

/// Resource limits of one simulation (InputError beyond them, with the numbers): cells =
/// length_mm / cell_size_mm within [3, kMaxCells]; time steps = simulated time / time_step_s at
/// most kMaxTimeSteps; cells x steps at most kMaxCellSteps (about a minute of one core). The
/// defaults (2 mm, 1 s) on the 6000 mm reference screw: 3000 cells x 7655 steps = 2.3e7.
inline constexpr double kMaxCells = 200000;
inline constexpr double kMaxTimeSteps = 2e6;
inline constexpr double kMaxCellSteps = 2e9;

/// Numerics of the simulation.
struct SimOptions {
  /// Simulated cutting time, s; 0 = the whole thread (Kinematics::cutting_time_s). Values beyond
  /// the cutting time are clamped to it (the heat stops at the thread end).
  double duration_s = 0.0;
  double cell_size_mm = 2.0;       ///< uniform finite-volume cell size, mm
  double time_step_s = 1.0;        ///< BDF2 time step, s
  double sample_interval_s = 1.0;  ///< spacing of the recorded curve, s (a multiple of the step)
  PhysicsConstants physics;        ///< material, heat transfer and cutting constants
  /// Verification hook: if >= 0, use this heat input (W) instead of the process model's.
  double heat_input_override_w = -1.0;
  /// Keep the final temperature profile in the result (cell_center_mm, temperature_rise_k).
  bool keep_final_profile = false;
  fit::SettleOptions settle;  ///< feature extraction from the recorded curve
};

/// Disturbances the prediction model cannot know (for honest comparisons), all seeded and
/// individually switchable. Off by default in the library; `whirl simulate` and `whirl dataset`
/// turn them on. Random numbers: std::mt19937_64 with the project's own uniform/normal mapping
/// (core/random.h), so results are identical across standard libraries.
/// Draw order from `seed`: heat-partition factor, expansion factor, drift rate, then one noise
/// value per recorded sample.
struct DisturbanceOptions {
  bool enabled = false;  ///< master switch
  std::uint64_t seed = 1;
  /// Per-workpiece heat partition factor (1 + heat_partition_rel_std * N(0,1)): tool wear, edge
  /// preparation, blank batch (assumption: a few percent).
  bool workpiece_variation = true;
  double heat_partition_rel_std = 0.03;  ///< -
  double expansion_rel_std = 0.02;       ///< alpha factor (1 + std * N(0,1)), - (material batch)
  /// Workshop drift: ambient temperature T_amb(t) = T_ref + r t, r ~ N(0, std) in K/h (assumption:
  /// a few tenths of a kelvin per hour). The screw follows through the surface-loss term and the
  /// chuck.
  bool ambient_drift = true;
  double ambient_drift_std_k_per_h = 0.2;
  /// When finite: the hall's rate r is given instead of drawn (the same hall as the machine's
  /// bed, machine_eval/machine_eval.h); the draw is still made, so every later draw is unchanged.
  double ambient_drift_fixed_k_per_h = std::numeric_limits<double>::quiet_NaN();
  /// Inductive-sensor noise on the recorded curve: N(0, std) per sample, std 0.25 um, i.e. about
  /// +-0.5 um (95 %).
  bool measurement_noise = true;
  double measurement_noise_std_um = 0.25;
  /// Tool wear (scenario): the heat input rises linearly over the cut, from 1 at t = 0 to
  /// 1 + tool_wear_heat_rise_rel at the end of the thread (flank wear raises the cutting force and
  /// the rubbing; assumption: +20 % over a 2 h tool life), -. Deterministic; 0 = off.
  double tool_wear_heat_rise_rel = 0.0;
  /// Friction heat of a steady rest riding on the blank (scenario): this power, W, spread
  /// over steady_rest_width_mm, steady_rest_offset_mm from the cut on the unmachined (chuck) side,
  /// moving with the whirling head. Deterministic; 0 = off (assumption: tens of W for a loaded
  /// rest pad).
  double steady_rest_heat_w = 0.0;
  double steady_rest_offset_mm = 300.0;  ///< distance from the cut towards the chuck, mm
  double steady_rest_width_mm = 20.0;    ///< axial contact width of the rest, mm
};

/// The disturbance values actually applied (1, 1, 0 when disabled).
struct AppliedDisturbances {
  double heat_partition_factor = 1.0;
  double expansion_factor = 1.0;
  double ambient_drift_k_per_h = 0.0;
  double measurement_noise_std_um = 0.0;
};

enum class SimTermination {
  kReachedDuration,   ///< stopped at the requested duration
  kReachedThreadEnd,  ///< the cut reached the end of the thread (duration_s = 0 or longer)
};
const char* ToString(SimTermination t);

/// Summary in the project's common shape (STYLE.md 1). The "cost" of a simulation is its energy
/// balance: heat in = heat stored + heat lost (surface, chuck, free end), with the loss integrated
/// in time by the trapezoidal rule.
struct SimulationSummary {
  int time_steps = 0;
  int cells = 0;
  double simulated_time_s = 0;
  double heat_in_j = 0;
  double heat_stored_j = 0;
  double heat_lost_j = 0;
  double energy_balance_rel_error = 0;  ///< |in - stored - lost| / in (0 when no heat), -
  double peak_temperature_rise_k = 0;   ///< largest section-mean rise seen, K
  SimTermination termination = SimTermination::kReachedDuration;
  std::string message;
  std::string BriefReport() const;
};

struct SimulationResult {
  /// Recorded elongation of the unmachined section at the cut point, um, at sample_interval_s from
  /// t = 0 over the simulated time (includes measurement noise when enabled).
  ElongationCurve curve;
  /// The same curve without measurement noise (the truth a compensation is judged against), um.
  std::vector<double> elongation_noise_free_um;
  screw::Kinematics kinematics;
  HeatInput heat;  ///< process-model heat input (before the disturbance factor)
  AppliedDisturbances disturbances;
  Features features;  ///< ExtractFeatures(curve, options.settle)
  SimulationSummary summary;
  std::vector<double> cell_center_mm;      ///< if keep_final_profile
  std::vector<double> temperature_rise_k;  ///< final section-mean rise over T_ref, if kept
};

/// Runs the simulation. Bad options (non-positive cell size, time step, ...) or an infeasible screw
/// throw InputError.
SimulationResult Simulate(const screw::Screw& screw, const SimOptions& options = {},
                          const DisturbanceOptions& disturbances = {});

}  // namespace whirl::sim
