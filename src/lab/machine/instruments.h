#pragma once
// What a shop can measure on the field machine (timeline.h), each with its own noise; nothing
// here returns a noise-free truth channel. Every record is known up to one constant (a probe or
// an interferometer is zeroed when set up): each reading carries the record's unknown zero,
// drawn N(0, 50 um) from the record's seed.
//   DayLog      temperatures of the machine's sensors (sensors.h) and the control's own duty
//               signals (SINUMERIK 840D system variables without extra wiring: $AA_S, $AA_LOAD,
//               $AA_IM, clock, program state; recalled from the system-variable list, check on
//               the control), one row per sample_s while the power is on. Columns: <sensor>_C,
//               and other columns power_on, ring_on, ring_rpm, ring_load_pct (drive power /
//               rated x 100 + N(0, 1)), cutting, z_speed_mm_min, z_position_mm, clock_min.
//               The first row is at power-on with the duty columns at 0. time_min = abs_min.
//               With FieldMachineConfig::blank_contact_std_k >= 0 also blank_contact_C: the
//               contact thermometer's reading of the latest blank clamped (20 before the first).
//   Probe       a check ring on the chuck read by a touch probe on the head at z_mm: m(t, z) +
//               zero + N(0, sigma) (Renishaw OMP40-2: 1.0 um 2 sigma repeatability plus
//               re-seating, estimate 1.0 um).
//   Laser       interferometer from the headstock end on a reflector on the carriage at z_mm:
//               the Z-axis part m_z(t, z) + zero per target + N(0, (0.3 um + 0.3 ppm z)^2)
//               (Renishaw XL-80 +-0.5 ppm with environment compensation; ISO 230-2).
//   Lead        a cut screw measured after cooling every step_mm: d(x) = [e + m - c](t) -
//               [e + m - c](0) + N(0, 0.5 um) per point + a per-screw scale error N(0, 1 um/m) x
//               x (temperature of measurement x alpha uncertainty; ISO 3408-3), where e - c (the
//               workpiece's elongation minus the applied compensation) is supplied by the caller.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "drift/run_file.h"
#include "machine/timeline.h"

namespace whirl::machine {

/// One reading of an instrument. value_um contains the record's unknown zero.
struct Reading {
  double abs_min = 0;
  double z_mm = 0;
  double value_um = 0;
  double sigma_um = 0;
};

struct LogOptions {
  double sample_s = 60;     ///< a multiple of the timeline's control sample
  bool sensors = true;
  bool duty = true;
  double load_noise_pct = 1.0;
};

/// The log of day d (sensors and/or duty), seeded. InputError if d is not in the calendar or
/// sample_s is not a multiple of the control sample.
drift::Run DayLog(const MachineTimeline& timeline, int day, const LogOptions& options,
                  std::uint64_t seed);

/// Probe readings of the check ring at the given times (abs_min, within power-on periods).
std::vector<Reading> ProbeReadings(const MachineTimeline& timeline,
                                   const std::vector<double>& abs_min, double z_mm,
                                   double sigma_um, std::uint64_t seed);

/// Laser readings at targets z_mm at the given times; one zero per target (readings ordered by
/// target, then time).
std::vector<Reading> LaserReadings(const MachineTimeline& timeline,
                                   const std::vector<double>& abs_min,
                                   const std::vector<double>& targets_mm, double noise_um,
                                   double noise_ppm, std::uint64_t seed);

struct LeadOptions {
  double step_mm = 10;
  double noise_um = 0.5;
  double scale_noise_um_per_m = 1.0;
};

/// Where a cut is: day and job index.
struct CutRef { int day = 0; int job = 0; };

/// Measured lead deviation of a cut screw: one Reading per step along the thread, x from the
/// thread start (z_mm holds x; abs_min the time the tool was there). workpiece_minus_comp_um(t)
/// = (e - c)(t) at cutting time t (s from the cut start): the caller's workpiece elongation minus
/// any compensation it applied. No unknown zero (a lead is a difference by definition).
std::vector<Reading> MeasureLead(const MachineTimeline& timeline, const CutRef& cut,
                                 const std::function<double(double t_s)>& workpiece_minus_comp_um,
                                 const LeadOptions& options, std::uint64_t seed);

/// The day log of day d (sensors and duty every sample_s) with one error channel, `offset_um`: a
/// displacement sensor against the check ring on the chuck read by the head at z_mm at every
/// row, ProbeReadings with N(0, sigma_um) noise, zeroed at the first row (the day's power-on:
/// the record's unknown zero is taken off, the first reading's noise stays in every row). What
/// `whirl machine sensors` writes for trying the drift commands on the field machine: on a real
/// machine such a channel is logged on warm-up tests; while cutting a shop reads the check ring
/// only at set-ups (field_history.h). time_min: minutes since the day's 00:00.
drift::Run CheckRingLog(const MachineTimeline& timeline, int day, double sample_s, double z_mm,
                        double sigma_um, std::uint64_t seed);

/// Control log of day d (for causal application): DayLog rows at the control sample from the
/// day's power-on to its power-off (sensors and duty), seeded; the caller takes the rows it may
/// use (those at or before the time of the compensation).
drift::Run ControlLog(const MachineTimeline& timeline, int day, std::uint64_t seed);

}  // namespace whirl::machine
