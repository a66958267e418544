#pragma once
// Machine thermal errors of a whirling machine and its virtual temperature sensors.
// The workpiece simulator (sim/simulator.h) gives the elongation e(t) of the unmachined section;
// this module adds the machine's own drift m(t, z) of the tool relative to the chuck, in the same
// sign convention (um, positive = the groove lands further towards the chuck, compare/cut.h), so
// the lead deviation of a cut is d(x) = [e + m - c](t) - [e + m - c](0). The parameters are in a
// machine JSON (schema "whirl.machine_thermal", version 1; shipped default
// datasets/machines/whirling_thermal.json, its README states the source or reasoning of every
// magnitude). Axis coordinate z = distance of the tool from the chuck face, mm (the cut runs from
// Kinematics::thread_start_position_mm towards the chuck: z(t) = z_start - v_f t).
//
// Heat sources (each a first-order response from a cold start at t = 0, f(t, tau) =
// 1 - exp(-t / tau), t and tau in min):
//   motor     ring-drive motor and bearing losses while the ring turns (idle and cutting):
//             S_motor(t) = P_idle f(t, tau_motor)                     [kW]
//   process   cutting heat reaching the head (ring bearing, coolant) while cutting only:
//             S_process(t) = P_cut f(t, tau_process)                  [kW]
//   z_screw   Z feed screw warming from its nut and bearings while the axis feeds (cutting only):
//             S_z(t) = R_z f(t, tau_z)                                [K]
//   ambient   the hall drifts linearly, T_amb(t) = T_0 + r t / 60 (r in K/h, drawn per day); the
//             bed follows with the lag tau_bed (first-order response to a ramp):
//             dT_bed(t) = r / 60 [t - tau_bed f(t, tau_bed)]          [K]
//
// Components of m(t, z), um (each switched by its `enabled`):
//   head      axial drift of the whirling head as it warms:
//             m_head = s_head [g_motor S_motor(t) + g_process S_process(t)]
//   z_screw   growth of the Z feed screw from its fixed bearing at z_fixed (the SD43910 case):
//             the nut moves away from the fixed end by alpha_s dT_s (z - z_fixed), i.e. towards
//             the chuck by m_z = 1000 alpha_s dT_s(t) (z_fixed - z),  dT_s = S_z + dT_bed
//             (the screw also follows the hall).
//   bed       the bed between the chuck face and the fixed bearing grows with the hall and moves
//             the fixed bearing (and so the tool) away from the chuck:
//             m_bed = -1000 alpha_b dT_bed(t) z_fixed.
// The workpiece's own response to the ambient drift stays in the workpiece simulator
// (sim::DisturbanceOptions::ambient_drift; the evaluation gives it the day's rate r, so blank and
// bed share one hall): with every machine component off, m = 0 and every result equals the
// workpiece-only one exactly.
//
// Variation: a machine seed scales g_motor, g_process, R_z and the three time constants each by
// (1 + machine_spread N(0,1)) (clamped to >= 0.2); a day seed draws the ambient rate
// r ~ N(0, ambient_rate_std) and the day's cutting power factor (1 + power_spread N(0,1)). The same
// seeds give the same machine and day on every platform (core/random.h).
//
// Virtual sensors: each named point i reads
//   T_i(t) = T_0 + a_i T_amb lag + sum_j g_ij L_i(S_j)(t) + noise,
// L_i a first-order lag with the sensor's tau_i (min) applied to each source (exact discretization
// with the input held over each 1/10 of the sample step), noise N(0, noise_std_K), then quantized
// to quantum_K (0.0625 K: a 12-bit digital sensor such as the DS18B20). Run files (drift format,
// drift/run_file.h) carry the temperatures and two error channels:
//   offset_um            m_head + m_bed, the z-independent part (m at z = z_fixed), um (what
//                        SD43900 compensates),
//   zscrew_per_1000_um   the screw growth over 1000 mm towards the chuck, 1e6 alpha_s dT_s, um
//                        (what SD43910 compensates: m_z = zscrew_per_1000 (z_fixed - z) / 1000).
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "drift/run_file.h"

namespace whirl::machine {

inline constexpr int kMachineSchemaVersion = 1;

enum class Source { kMotor, kProcess, kZScrew, kAmbient };
inline constexpr int kSourceCount = 4;

struct HeadComponent {
  bool enabled = true;
  int sign = 1;                       ///< +1: head growth moves the tool towards the chuck
  double idle_power_kw = 1.5;         ///< P_idle, ring turning, kW
  double cutting_power_kw = 1.5;      ///< P_cut at 180 m/min, kW; scales with v_c / 180 m/min
  double motor_gain_um_per_kw = 6;    ///< g_motor, um per kW at steady state
  double motor_tau_min = 35;          ///< tau_motor, min
  double process_gain_um_per_kw = 3;  ///< g_process, um per kW
  double process_tau_min = 12;        ///< tau_process, min
};

struct ZScrewComponent {
  bool enabled = true;
  double expansion_per_k = 11.5e-6;  ///< alpha_s, 1/K (steel)
  double steady_rise_k = 0.5;        ///< R_z, K
  double tau_min = 40;               ///< tau_z, min
  double fixed_end_mm = 6400;        ///< z_fixed, mm from the chuck face
};

struct AmbientComponent {
  bool enabled = true;
  double expansion_per_k = 10.5e-6;  ///< alpha_b, 1/K (cast iron bed)
  double bed_tau_min = 90;           ///< tau_bed, min
  double rate_std_k_per_h = 0.3;     ///< std of the day's ambient rate r, K/h
  double start_c = 20.0;             ///< T_0, degC
};

struct SensorSpec {
  std::string name;               ///< column name without the _C suffix
  double ambient_weight = 1.0;    ///< a_i: 1 follows the hall, 0 insulated
  std::array<double, 3> gains{};  ///< g_i for motor [K/kW], process [K/kW], z_screw [K/K]
  double tau_min = 5;             ///< tau_i, min (> 0)
};

struct MachineConfig {
  std::string name = "whirling-machine";
  HeadComponent head;
  ZScrewComponent z_screw;
  AmbientComponent ambient;
  double machine_spread = 0.15;  ///< relative std of the per-machine factors
  double power_spread = 0.1;     ///< relative std of the per-day cutting power
  double noise_std_k = 0.03;     ///< sensor noise, K
  double quantum_k = 0.0625;     ///< sensor resolution, K (0 = none)
  double sample_min = 1.0;       ///< sensor sample step, min
  std::vector<SensorSpec> sensors;
  /// Every component off (m = 0).
  void DisableAll();
  void Validate(const std::string& where) const;
};

/// The default machine (the values above and 12 named sensors), equal to the shipped JSON.
MachineConfig DefaultMachine();
void to_json(nlohmann::json& j, const MachineConfig& m);
/// "schema": "whirl.machine_thermal" and "schema_version": 1 are required, every other key is
/// optional (the default above); unknown keys are rejected.
void from_json(const nlohmann::json& j, MachineConfig& m);
/// from_json, then Validate: every number within its physical range (powers [0, 100] kW, time
/// constants (0, 10000] min, expansion coefficients [0, 1e-4] 1/K, spreads [0, 1], sensor noise
/// and quantum [0, 10] K, sample step (0, 1440] min, ...; machine.cpp states each). InputError
/// names the file, the field, the value and the range.
MachineConfig ReadMachine(const std::string& path);

/// One machine on one day: the drawn parameters (seeded), closed forms of m.
struct MachineDay {
  MachineConfig config;  ///< with the per-machine factors applied
  double ambient_rate_k_per_h = 0;
  double power_factor = 1;
  /// Draws the machine (machine_seed) and the day (day_seed).
  static MachineDay Draw(const MachineConfig& config, std::uint64_t machine_seed,
                         std::uint64_t day_seed);
  /// Source states at time t_min of a run: cutting = the process and the Z axis are on;
  /// cutting_speed scales P_cut (v_c / 180).
  double Source(Source s, double t_min, bool cutting, double cutting_speed_m_min) const;
  double BedRiseK(double t_min) const;                          ///< dT_bed
  double HeadUm(double t_min, bool cutting, double v_c) const;  ///< m_head
  double ZScrewPer1000Um(double t_min, bool cutting) const;     ///< 1e6 alpha_s dT_s
  double BedUm(double t_min) const;                             ///< m_bed
  /// m(t, z) = m_head + m_z + m_bed at the tool position z_mm.
  double DriftUm(double t_min, double z_mm, bool cutting, double v_c) const;
};

struct RunSpec {
  std::string name;
  drift::RunState state = drift::RunState::kCutting;
  double duration_min = 120;
  double cutting_speed_m_min = 180;  ///< cutting runs
  std::uint64_t noise_seed = 1;
};

/// A virtual-sensor run (temperatures, offset_um, zscrew_per_1000_um), sampled every sample_min.
drift::Run SimulateRun(const MachineDay& day, const RunSpec& spec);

/// Provenance lines for written run files.
std::vector<std::string> RunComments(const MachineDay& day, std::uint64_t machine_seed,
                                     std::uint64_t day_seed, const RunSpec& spec);

}  // namespace whirl::machine
