#include "machine/scenarios.h"

#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/random.h"
#include "machine/instruments.h"

namespace whirl::machine {

namespace {

MachineScenario Production() {
  MachineScenario s;
  s.name = "production";
  s.description = "one shift, set-ups, breaks, random screws, conditioned hall";
  s.hall = HallOptions::Conditioned();
  return s;
}

}  // namespace

std::vector<MachineScenario> MachineScenarios() {
  std::vector<MachineScenario> all;
  MachineScenario constant = Production();
  constant.name = "constant-duty";
  constant.description = "field machine, one cut per day right after power-on, hall ramp";
  constant.day.one_cut_per_day = true;
  constant.hall = HallOptions::Ramp();
  all.push_back(constant);
  all.push_back(Production());
  MachineScenario duty = Production();
  duty.name = "duty-changes";
  duty.description = "production with alternating extreme screws and idle ring runs";
  duty.jobs.alternate = true;
  duty.jobs.min.cutting_speed_m_min = 150, duty.jobs.max.cutting_speed_m_min = 160;
  duty.jobs.min.diameter_mm = 50, duty.jobs.max.diameter_mm = 60;
  duty.jobs.min2 = duty.jobs.min, duty.jobs.max2 = duty.jobs.max;
  duty.jobs.min2.cutting_speed_m_min = 200, duty.jobs.max2.cutting_speed_m_min = 210;
  duty.jobs.min2.diameter_mm = 90, duty.jobs.max2.diameter_mm = 100;
  duty.day.idle_probability = 0.5;
  duty.day.idle_min_hi = 30;
  all.push_back(duty);
  MachineScenario interrupted = Production();
  interrupted.name = "interrupted-starts";
  interrupted.description = "two shifts, breaks, extra stops of 30-120 min after half the set-ups";
  interrupted.day.shift_end_min = 1320;
  interrupted.day.breaks = {{600, 30}, {840, 30}, {1080, 30}};
  interrupted.day.stop_probability = 0.5;
  all.push_back(interrupted);
  MachineScenario hall = Production();
  hall.name = "unconditioned-hall";
  hall.description = "production in an unconditioned hall (2.5 K diurnal, door events)";
  hall.hall = HallOptions::Unconditioned();
  all.push_back(hall);
  MachineScenario scale = Production();
  scale.name = "linear-scale";
  scale.description = "production with a linear scale on Z (the screw leaves the loop)";
  scale.z_feedback = ZFeedback::kScale;
  all.push_back(scale);
  return all;
}

const MachineScenario& FindMachineScenario(const std::string& name) {
  static const std::vector<MachineScenario> all = MachineScenarios();
  for (const MachineScenario& s : all)
    if (s.name == name) return s;
  std::string names;
  for (const MachineScenario& s : all) names += (names.empty() ? "" : ", ") + s.name;
  throw InputError("machine scenario '" + name + "' is not one of: " + names);
}

std::vector<MachineScenario> SelectMachineScenarios(const std::string& list,
                                                    const std::string& flag) {
  if (list == "all") return MachineScenarios();
  std::vector<MachineScenario> out;
  std::stringstream in(list);
  std::string name;
  while (std::getline(in, name, ',')) {
    try {
      out.push_back(FindMachineScenario(name));
    } catch (const InputError& e) {
      throw InputError(flag + ": " + e.what());
    }
  }
  if (out.empty()) throw InputError(flag + ": no scenario named (give a list or 'all')");
  return out;
}

std::uint64_t MachineSeed(std::uint64_t seed, int machine_index) {
  return MixSeed(seed, 0x4d00 + static_cast<std::uint64_t>(machine_index));
}

std::vector<DayPlan> PlanCalendar(const MachineScenario& scenario, std::uint64_t machine_seed,
                                  const CalendarSpec& spec, double power_spread) {
  const int history = static_cast<int>(spec.warmup_speeds_m_min.size()) + spec.laser_tests +
                      spec.past_days;
  const int weeks = (history + 4) / 5;
  std::vector<DayPlan> days;
  int d = -7 * std::max(1, weeks);
  auto next_workday = [&]() {
    while (!IsWorkday(d)) ++d;
    return d++;
  };
  const double start = scenario.day.shift_start_min;
  for (double v : spec.warmup_speeds_m_min)
    days.push_back(WarmupTestDay(next_workday(), machine_seed, start,
                                 RingRpm(v, spec.warmup_tool_circle_mm), spec.warmup_on_min,
                                 spec.warmup_off_min));
  for (int i = 0; i < spec.laser_tests; ++i)
    days.push_back(LaserTestDay(next_workday(), machine_seed, start, spec.laser_feed_mm_min,
                                spec.laser_z_lo_mm, spec.laser_z_hi_mm, spec.laser_on_min,
                                spec.laser_off_min));
  for (int i = 0; i < spec.past_days; ++i) {
    days.push_back(PlanDay(scenario.day, next_workday(), machine_seed, scenario.jobs, power_spread));
    days.back().role = DayRole::kHistory;
  }
  if (d > 0) throw InputError("calendar: history runs into the test window");
  d = 0;
  for (int i = 0; i < spec.test_days; ++i)
    days.push_back(PlanDay(spec.test_day_options.value_or(scenario.day), next_workday(),
                           machine_seed, scenario.jobs, power_spread));
  ClassifyStarts(days);
  return days;
}

MachineWorld BuildMachineWorld(const FieldMachineConfig& config, const MachineScenario& scenario,
                               std::uint64_t seed, int machine_index, const CalendarSpec& spec,
                               const TimelineOptions& options) {
  MachineWorld world;
  world.machine_seed = MachineSeed(seed, machine_index);
  FieldMachineConfig c = config;
  if (scenario.z_feedback) c.z.feedback = *scenario.z_feedback;
  const FieldMachine machine(c, world.machine_seed);
  std::vector<DayPlan> days = PlanCalendar(scenario, world.machine_seed, spec, c.power_spread);
  const HallProfile hall(scenario.hall, days.front().day, days.back().day + 1,
                         MixSeed(world.machine_seed, 0x68616c6c));
  world.timeline = SimulateCalendar(machine, hall, std::move(days), options);
  return world;
}

std::vector<drift::Run> ShopDayLogs(const MachineScenario& scenario, std::uint64_t seed,
                                    int warmup_tests, int production_days, double probe_z_mm,
                                    double noise_um) {
  for (const auto& [n, what] : {std::pair{warmup_tests, "warm-up tests"},
                                std::pair{production_days, "production days"}})
    if (n < 0 || n > 20)
      throw InputError(std::string(what) + " = " + std::to_string(n) + ": must be within 0..20");
  CalendarSpec spec;
  spec.warmup_speeds_m_min.clear();
  for (int i = 0; i < warmup_tests; ++i)
    spec.warmup_speeds_m_min.push_back(
        warmup_tests == 1 ? 180.0 : 150.0 + 60.0 * i / (warmup_tests - 1));
  spec.laser_tests = 0;
  spec.past_days = production_days;
  spec.test_days = 1;
  const MachineWorld world = BuildMachineWorld(DefaultFieldMachine(), scenario, seed, 0, spec);
  std::vector<drift::Run> runs;
  int idle = 0, cutting = 0;
  for (const DayPlan& plan : world.timeline.days()) {
    if (plan.day >= 0 || plan.role == DayRole::kLaserTest) continue;
    drift::Run run = CheckRingLog(world.timeline, plan.day, 60, probe_z_mm, noise_um, plan.seed);
    const bool warmup = plan.role == DayRole::kWarmupTest;
    run.state = warmup ? drift::RunState::kIdle : drift::RunState::kCutting;
    run.name = warmup ? "idle_" + std::to_string(++idle) : "cutting_" + std::to_string(++cutting);
    runs.push_back(std::move(run));
  }
  return runs;
}

}  // namespace whirl::machine
