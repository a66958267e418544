#pragma once
// A shop's day on the whirling machine: a calendar of days (day index d signed, history d < 0 <=
// test days; weekday = d mod 7, 0 = Monday, Saturday and Sunday off) and a plan per working day.
// Times on a day are its clock, minutes after midnight; absolute time abs_min = d 1440 + clock.
// Rules of PlanDay (shop practice; breaks after the German working-time act, Arbeitszeitgesetz
// section 4: 30 min for 6-9 h of work, may be split into 15-min parts):
//   power on at shift start; per job a set-up U(setup_min) (ring off; a rapid traverse to the start
//   position), an optional idle ring run, the cut (thread / v_f), unload 10 min; a cut in progress
//   runs on through a break (whirling runs unattended and must not stop in the groove: a dwell
//   marks the raceway); a set-up or unload that meets a break is extended by it; a cut is not
//   started if it would end more than late_end_min after shift end; power off after the last
//   unload or at shift end. Start types per cut: cold (first cut after >= 8 h off), warm (pause
//   since the last cut <= 45 min), interrupted (45-180 min), long_pause (> 180 min, same day).
#include <cstdint>
#include <string>
#include <vector>

#include "core/process.h"
#include "screw/screw.h"

namespace whirl::machine {

enum class EventKind { kPowerOn, kSetup, kWarmupIdle, kCut, kUnload, kBreak, kStop,
                       kCheck, kLaserCycle, kPowerOff };
std::string ToString(EventKind k);

enum class StartType { kCold, kWarm, kInterrupted, kLongPause };
std::string ToString(StartType t);  ///< "cold", "warm", "interrupted", "long_pause"

/// What a day is for (the evaluation's history protocol, the test window).
enum class DayRole { kWarmupTest, kLaserTest, kHistory, kTest };
std::string ToString(DayRole r);

/// One screw on the machine: its inputs and what the machine sees of it.
struct Job {
  screw::Screw screw;
  screw::Kinematics kinematics;    ///< of screw (v_f, ring speed, thread positions)
  double cutting_power_w = 0;    ///< Kienzle power of the cut (sim::ComputeHeatInput)
  double idle_before_min = 0;    ///< idle ring run before the cut
  // Filled by the layout:
  double cut_start_min = 0, cut_end_min = 0;  ///< day clock
  double pause_before_min = 0;   ///< since the previous cut ended (or power-on history)
  StartType start_type = StartType::kCold;
};

/// An interval of the day. ring_rpm > 0 while the ring turns; z_* describe the Z axis.
struct ScheduleEvent {
  EventKind kind = EventKind::kSetup;
  double start_min = 0, end_min = 0;  ///< day clock
  int job = -1;                       ///< index into DayPlan::jobs (cuts, set-ups, idles)
  double ring_rpm = 0;                ///< warm-up idles and laser-free idle tests
  double z_from_mm = 0, z_to_mm = 0;  ///< axis travel over the event (rapid or cut)
  double feed_mm_min = 0;             ///< laser cycle: the axis feed (end to end and back)
};

struct DayPlan {
  int day = 0;
  DayRole role = DayRole::kTest;
  std::uint64_t seed = 0;             ///< DaySeed(machine_seed, day)
  double power_factor = 1;            ///< cutting power factor of the day (1 + power_spread N)
  std::vector<Job> jobs;
  std::vector<ScheduleEvent> events;  ///< ordered, non-overlapping; power_on first, off last
  double power_on_min() const;
  double power_off_min() const;
};

struct Break { double clock_min, duration_min; };

struct DayOptions {
  double shift_start_min = 360;       ///< 06:00
  double shift_end_min = 870;         ///< 14:30 (one shift); two shifts: 1320 (22:00)
  std::vector<Break> breaks{{540, 15}, {720, 30}};
  double setup_min_lo = 20, setup_min_hi = 40;
  double unload_min = 10;
  double late_end_min = 60;           ///< a cut may end this long after shift end
  double idle_probability = 0;        ///< share of cuts preceded by an idle ring run
  double idle_min_hi = 30;            ///< idle run U(0, this) min
  double stop_probability = 0;        ///< share of set-ups followed by an extra stop
  double stop_min_lo = 30, stop_min_hi = 120;
  int max_jobs = 8;
  bool one_cut_per_day = false;       ///< constant-duty: one cut right after power-on
  double rapid_mm_min = 10000;        ///< rapid traverse of the Z axis
};

/// How the day's screws are drawn: uniformly within ranges like the network's training ranges
/// (compare/evaluate.h InputRanges), or alternating between two ranges (duty changes).
struct JobMix {
  ProcessInputs min{60, 50, 6, 3, 150};
  ProcessInputs max{65, 100, 16, 10, 210};
  bool alternate = false;              ///< alternate between (min, max) and (min2, max2)
  ProcessInputs min2{60, 90, 6, 3, 200};
  ProcessInputs max2{65, 100, 16, 10, 210};
  screw::Screw base = screw::ReferenceScrew();  ///< length, thread, settings of every screw
};

/// Seed of day d of a machine: MixSeed(machine_seed, 0x646179000000 + (d + 2^20)); distinct for
/// distinct d (|d| < 2^20), so history and test days never share a seed.
std::uint64_t DaySeed(std::uint64_t machine_seed, int day);
int Weekday(int day);  ///< 0 = Monday .. 6 = Sunday
bool IsWorkday(int day);

/// Draws a feasible screw (sim::ValidateScrew) of the mix; `alternate_index` picks the range.
Job DrawJob(const JobMix& mix, std::uint64_t seed, int alternate_index);
/// Fills kinematics and cutting power of a screw (sim::ComputeKinematics, ComputeHeatInput).
Job MakeJob(const screw::Screw& screw);

/// A production day: the job list drawn first, then laid out by the rules above.
DayPlan PlanDay(const DayOptions& options, int day, std::uint64_t machine_seed, const JobMix& mix,
                double power_spread);
/// Warm-up test (ISO 230-3): power on at shift start, ring idle at ring_rpm for on_min, ring off
/// for off_min (power stays on), power off. Check readings are taken by instruments.h.
DayPlan WarmupTestDay(int day, std::uint64_t machine_seed, double shift_start_min, double ring_rpm,
                      double on_min, double off_min);
/// Z laser warm-up: the axis cycles end to end (z_lo_mm <-> z_hi_mm) at feed_mm_min for on_min,
/// then stands for off_min; ring off.
DayPlan LaserTestDay(int day, std::uint64_t machine_seed, double shift_start_min,
                     double feed_mm_min, double z_lo_mm, double z_hi_mm, double on_min,
                     double off_min);
/// Ring speed (1/min) of cutting speed v_c on the tool circle of a screw of diameter D.
double RingRpm(double cutting_speed_m_min, double tool_circle_mm);

/// Start types of the cuts of consecutive days (the calendar's whole history decides "cold").
void ClassifyStarts(std::vector<DayPlan>& days);

}  // namespace whirl::machine
