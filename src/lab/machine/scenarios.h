#pragma once
// Named scenarios of the one machine world of the evaluation: a field machine (field.h) living a
// shop's calendar (day.h) in a hall (hall.h):
//   constant-duty       one cut per day right after power-on (>= 15.5 h off), hall ramp
//                       N(0, 0.3 K/h): the old protocol in the new physics (elapsed time should win)
//   production          one shift 06:00-14:30, breaks 09:00 (15) and 12:00 (30), set-up
//                       U(20, 40) min, unload 10 min, random screws, conditioned hall (default)
//   duty-changes        as production, jobs alternate between extremes (v_c 150-160 / 200-210
//                       m/min, D 50-60 / 90-100 mm), half the cuts after an idle ring run U(0, 30)
//   interrupted-starts  two shifts 06:00-22:00, breaks 10:00, 14:00, 18:00 (30), with p = 0.5 an
//                       extra stop U(30, 120) min after a set-up (crane, measuring, fault)
//   unconditioned-hall  as production in an unconditioned hall (2.5 K diurnal, doors)
//   linear-scale        as production with a linear scale on Z (the screw leaves the loop)
// The magnitudes are fixed before any result is seen (docs/machine-truth.md).
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "drift/run_file.h"
#include "machine/day.h"
#include "machine/field.h"
#include "machine/hall.h"
#include "machine/timeline.h"

namespace whirl::machine {

struct MachineScenario {
  std::string name;
  std::string description;  ///< one line
  DayOptions day;
  JobMix jobs;
  HallOptions hall;
  std::optional<ZFeedback> z_feedback;  ///< override of the machine file's feedback
};

/// Every scenario, in the order above.
std::vector<MachineScenario> MachineScenarios();
/// "a,b,c" or "all"; InputError naming `flag`, the bad name and the valid names.
std::vector<MachineScenario> SelectMachineScenarios(const std::string& list,
                                                    const std::string& flag = "--scenarios");
const MachineScenario& FindMachineScenario(const std::string& name);

/// Which days a machine's calendar holds (the evaluation's history protocol decides the counts).
/// Layout from Monday of week 0 (day index d0 = -7 (1 + weeks of history)): warm-up tests on
/// consecutive workdays, then laser tests, then past production days; test days from d = 0
/// (workdays only, weekends simulated as off time).
struct CalendarSpec {
  std::vector<double> warmup_speeds_m_min{150, 210};  ///< one warm-up test per entry
  double warmup_on_min = 180, warmup_off_min = 90;
  double warmup_tool_circle_mm = 86;  ///< tool circle for the idle speed (reference screw)
  int laser_tests = 1;
  double laser_feed_mm_min = 2000, laser_on_min = 120, laser_off_min = 60;
  double laser_z_lo_mm = 500, laser_z_hi_mm = 5500;
  int past_days = 5;   ///< production days of the scenario before the test window
  int test_days = 2;   ///< production days from d = 0
  /// A shift-pattern change between the training and the test weeks: the test days planned with
  /// these day rules (shift times, breaks, stops; e.g. another scenario's) instead of the
  /// scenario's; unset (the default): the scenario's.
  std::optional<DayOptions> test_day_options;
};

/// The calendar of one machine (day plans with roles), seeded by the machine seed.
std::vector<DayPlan> PlanCalendar(const MachineScenario& scenario, std::uint64_t machine_seed,
                                  const CalendarSpec& spec, double power_spread);

/// Seed of machine i of a run: MixSeed(seed, 0x4d00 + i).
std::uint64_t MachineSeed(std::uint64_t seed, int machine_index);

/// One machine of a field scenario, simulated over its calendar.
struct MachineWorld {
  std::uint64_t machine_seed = 0;
  MachineTimeline timeline;  ///< days(), machine(), hall() inside
};

/// The day logs `whirl machine sensors` writes: machine 0 of `scenario` (seed `seed`) with
/// `warmup_tests` warm-up tests (ring idle at speeds spread over 150..210 m/min; 180 m/min for
/// one) and `production_days` past production days, no laser test; each day as
/// instruments.h CheckRingLog (one row per minute, the check ring at `probe_z_mm`, displacement
/// noise `noise_um`), state idle for a warm-up test and cutting for a production day, named
/// idle_<n> and cutting_<n> in calendar order. InputError for counts outside 0..20.
std::vector<drift::Run> ShopDayLogs(const MachineScenario& scenario, std::uint64_t seed,
                                    int warmup_tests, int production_days, double probe_z_mm,
                                    double noise_um);

/// Draws machine i of the scenario (config with the scenario's Z override), its hall (seed
/// MixSeed(machine_seed, 0x68616c6c)) and calendar, and simulates it.
MachineWorld BuildMachineWorld(const FieldMachineConfig& config, const MachineScenario& scenario,
                               std::uint64_t seed, int machine_index, const CalendarSpec& spec,
                               const TimelineOptions& options = {});

}  // namespace whirl::machine
