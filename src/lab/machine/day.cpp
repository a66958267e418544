#include "machine/day.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"
#include "sim/physics.h"

namespace whirl::machine {

namespace {

constexpr double kParkMm = 6000;  // Z parked near the tailstock end between jobs

ScheduleEvent Event(EventKind kind, double start, double end, int job = -1) {
  ScheduleEvent e;
  e.kind = kind;
  e.start_min = start;
  e.end_min = end;
  e.job = job;
  return e;
}

// Lays out a day: the clock, the breaks not yet taken, the events.
struct Layout {
  const DayOptions& options;
  std::vector<bool> taken;
  std::vector<ScheduleEvent> events;
  double t = 0;
  double z = kParkMm;

  // An interruptible activity (set-up, unload, stop): extended by any break it meets.
  void Interruptible(EventKind kind, double duration, int job, double z_to) {
    double left = duration;
    while (left > 1e-9) {
      const int b = NextBreak(t + left);
      if (b < 0) {
        Push(kind, t, t + left, job, z_to);
        return;
      }
      const Break& br = options.breaks[b];
      if (br.clock_min > t) {
        left -= br.clock_min - t;
        Push(kind, t, br.clock_min, job, z_to);
      }
      Push(EventKind::kBreak, std::max(t, br.clock_min), br.clock_min + br.duration_min, -1, z);
      taken[b] = true;
    }
  }
  // An unattended activity (idle ring run, cut): runs through breaks, which count as taken.
  void Unattended(ScheduleEvent e) {
    for (std::size_t b = 0; b < taken.size(); ++b)
      if (!taken[b] && options.breaks[b].clock_min < e.end_min) taken[b] = true;
    z = e.z_to_mm;
    t = e.end_min;
    events.push_back(e);
  }
  // First break not taken that starts before `until` (and has not ended before t).
  int NextBreak(double until) const {
    for (std::size_t b = 0; b < taken.size(); ++b)
      if (!taken[b] && options.breaks[b].clock_min < until) return static_cast<int>(b);
    return -1;
  }
  void Push(EventKind kind, double start, double end, int job, double z_to) {
    ScheduleEvent e = Event(kind, start, end, job);
    e.z_from_mm = z;
    e.z_to_mm = z_to;
    z = z_to;
    t = end;
    events.push_back(e);
  }
};

double DrawIn(Rng& rng, double lo, double hi) { return lo + (hi - lo) * rng.Uniform(); }

}  // namespace

std::string ToString(EventKind k) {
  switch (k) {
    case EventKind::kPowerOn: return "power_on";
    case EventKind::kSetup: return "setup";
    case EventKind::kWarmupIdle: return "warmup_idle";
    case EventKind::kCut: return "cut";
    case EventKind::kUnload: return "unload";
    case EventKind::kBreak: return "break";
    case EventKind::kStop: return "stop";
    case EventKind::kCheck: return "checks";
    case EventKind::kLaserCycle: return "laser_cycle";
    case EventKind::kPowerOff: return "power_off";
  }
  return "?";
}

std::string ToString(StartType t) {
  switch (t) {
    case StartType::kCold: return "cold";
    case StartType::kWarm: return "warm";
    case StartType::kInterrupted: return "interrupted";
    case StartType::kLongPause: return "long_pause";
  }
  return "?";
}

std::string ToString(DayRole r) {
  switch (r) {
    case DayRole::kWarmupTest: return "warmup_test";
    case DayRole::kLaserTest: return "laser_test";
    case DayRole::kHistory: return "history";
    case DayRole::kTest: return "test";
  }
  return "?";
}

double DayPlan::power_on_min() const { return events.empty() ? 0 : events.front().start_min; }
double DayPlan::power_off_min() const { return events.empty() ? 0 : events.back().end_min; }

std::uint64_t DaySeed(std::uint64_t machine_seed, int day) {
  if (std::abs(day) >= (1 << 20)) throw InputError("day index out of range: " + std::to_string(day));
  return MixSeed(machine_seed, 0x646179000000ull + static_cast<std::uint64_t>(day + (1 << 20)));
}

int Weekday(int day) { return ((day % 7) + 7) % 7; }
bool IsWorkday(int day) { return Weekday(day) < 5; }

double RingRpm(double cutting_speed_m_min, double tool_circle_mm) {
  return cutting_speed_m_min * 1000.0 / (kPi * tool_circle_mm);
}

Job MakeJob(const screw::Screw& screw) {
  Job job;
  job.screw = screw;
  job.kinematics = screw::ComputeKinematics(screw);
  job.cutting_power_w =
      sim::ComputeHeatInput(screw, job.kinematics, sim::PhysicsConstants{}).cutting_power_w;
  return job;
}

Job DrawJob(const JobMix& mix, std::uint64_t seed, int alternate_index) {
  const bool second = mix.alternate && alternate_index % 2 == 1;
  const auto lo = (second ? mix.min2 : mix.min).ToArray();
  const auto hi = (second ? mix.max2 : mix.max).ToArray();
  Rng rng(seed);
  for (int attempt = 0; attempt < 1000; ++attempt) {
    std::array<double, ProcessInputs::kCount> x{};
    for (int i = 0; i < ProcessInputs::kCount; ++i) x[i] = DrawIn(rng, lo[i], hi[i]);
    screw::Screw screw = mix.base;
    screw.process = ProcessInputs::FromArray(x);
    screw.name = "job";
    try {
      screw::ValidateScrew(screw);
    } catch (const InputError&) {
      continue;
    }
    return MakeJob(screw);
  }
  throw InputError("job mix: 1000 infeasible screws in a row (ranges too wide for the lead?)");
}

namespace {

DayPlan NewDay(int day, std::uint64_t machine_seed, DayRole role) {
  DayPlan plan;
  plan.day = day;
  plan.role = role;
  plan.seed = DaySeed(machine_seed, day);
  return plan;
}

// Lays out one job (set-up, optional stop, idle, cut, unload); false if the cut would end too late.
bool LayOutJob(Layout& lay, DayPlan& plan, int j, Rng& rng) {
  const DayOptions& o = lay.options;
  Job& job = plan.jobs[j];
  const double setup = o.one_cut_per_day ? 0 : DrawIn(rng, o.setup_min_lo, o.setup_min_hi);
  const bool stop = rng.Uniform() < o.stop_probability;
  const double stop_min = DrawIn(rng, o.stop_min_lo, o.stop_min_hi);
  const double cut_min = job.kinematics.cutting_time_s / 60;
  const double z_start = job.kinematics.thread_start_position_mm;
  if (lay.t + setup + job.idle_before_min + cut_min > o.shift_end_min + o.late_end_min) return false;
  if (setup > 0) lay.Interruptible(EventKind::kSetup, setup, j, z_start);
  lay.z = z_start;
  if (stop && !o.one_cut_per_day) lay.Interruptible(EventKind::kStop, stop_min, j, z_start);
  if (lay.t + job.idle_before_min + cut_min > o.shift_end_min + o.late_end_min) return false;
  if (job.idle_before_min > 0) {
    // An idle run that would end inside a break idles on until the operator is back: no cut
    // starts inside a break.
    for (const Break& b : o.breaks) {
      const double end = lay.t + job.idle_before_min, b_end = b.clock_min + b.duration_min;
      if (end > b.clock_min && end < b_end) job.idle_before_min = b_end - lay.t;
    }
    ScheduleEvent idle = Event(EventKind::kWarmupIdle, lay.t, lay.t + job.idle_before_min, j);
    idle.ring_rpm = job.kinematics.ring_speed_rpm;
    idle.z_from_mm = idle.z_to_mm = z_start;
    lay.Unattended(idle);
  }
  ScheduleEvent cut = Event(EventKind::kCut, lay.t, lay.t + cut_min, j);
  cut.ring_rpm = job.kinematics.ring_speed_rpm;
  cut.z_from_mm = z_start;
  cut.z_to_mm = job.kinematics.thread_end_position_mm;
  job.cut_start_min = cut.start_min;
  job.cut_end_min = cut.end_min;
  lay.Unattended(cut);
  lay.Interruptible(EventKind::kUnload, o.unload_min, j, lay.z);
  return true;
}

}  // namespace

DayPlan PlanDay(const DayOptions& options, int day, std::uint64_t machine_seed, const JobMix& mix,
                double power_spread) {
  if (!IsWorkday(day)) throw InputError("day " + std::to_string(day) + " is not a workday");
  DayPlan plan = NewDay(day, machine_seed, DayRole::kTest);
  Rng rng(plan.seed);
  plan.power_factor = std::max(0.3, 1.0 + power_spread * rng.Normal());
  const int jobs = options.one_cut_per_day ? 1 : options.max_jobs;
  for (int j = 0; j < jobs; ++j) {
    Job job = DrawJob(mix, MixSeed(plan.seed, 100 + j), j);
    if (rng.Uniform() < options.idle_probability)
      job.idle_before_min = DrawIn(rng, 0, options.idle_min_hi);
    plan.jobs.push_back(job);
  }
  Layout lay{options, std::vector<bool>(options.breaks.size(), false), {}, options.shift_start_min};
  lay.events.push_back(Event(EventKind::kPowerOn, lay.t, lay.t));
  std::size_t laid = 0;
  while (laid < plan.jobs.size() && LayOutJob(lay, plan, static_cast<int>(laid), rng)) ++laid;
  plan.jobs.resize(laid);
  const double off = std::max(lay.t, options.one_cut_per_day ? lay.t : options.shift_end_min);
  lay.events.push_back(Event(EventKind::kPowerOff, off, off));
  lay.events.back().z_from_mm = lay.events.back().z_to_mm = lay.z;
  plan.events = std::move(lay.events);
  return plan;
}

DayPlan WarmupTestDay(int day, std::uint64_t machine_seed, double shift_start_min, double ring_rpm,
                      double on_min, double off_min) {
  DayPlan plan = NewDay(day, machine_seed, DayRole::kWarmupTest);
  const double t0 = shift_start_min, probe_z = 150;
  plan.events.push_back(Event(EventKind::kPowerOn, t0, t0));
  ScheduleEvent idle = Event(EventKind::kWarmupIdle, t0, t0 + on_min);
  idle.ring_rpm = ring_rpm;
  plan.events.push_back(idle);
  plan.events.push_back(Event(EventKind::kCheck, t0 + on_min, t0 + on_min + off_min));
  plan.events.push_back(Event(EventKind::kPowerOff, t0 + on_min + off_min, t0 + on_min + off_min));
  for (auto& e : plan.events) e.z_from_mm = e.z_to_mm = probe_z;
  return plan;
}

DayPlan LaserTestDay(int day, std::uint64_t machine_seed, double shift_start_min,
                     double feed_mm_min, double z_lo_mm, double z_hi_mm, double on_min,
                     double off_min) {
  DayPlan plan = NewDay(day, machine_seed, DayRole::kLaserTest);
  const double t0 = shift_start_min;
  plan.events.push_back(Event(EventKind::kPowerOn, t0, t0));
  ScheduleEvent cycle = Event(EventKind::kLaserCycle, t0, t0 + on_min);
  cycle.z_from_mm = z_lo_mm;
  cycle.z_to_mm = z_hi_mm;
  cycle.feed_mm_min = feed_mm_min;
  plan.events.push_back(cycle);
  ScheduleEvent stand = Event(EventKind::kCheck, t0 + on_min, t0 + on_min + off_min);
  stand.z_from_mm = stand.z_to_mm = z_lo_mm;
  plan.events.push_back(stand);
  plan.events.push_back(Event(EventKind::kPowerOff, stand.end_min, stand.end_min));
  plan.events.back().z_from_mm = plan.events.back().z_to_mm = z_lo_mm;
  plan.events.front().z_from_mm = plan.events.front().z_to_mm = z_lo_mm;
  return plan;
}

void ClassifyStarts(std::vector<DayPlan>& days) {
  std::sort(days.begin(), days.end(), [](const DayPlan& a, const DayPlan& b) { return a.day < b.day; });
  double last_heat_end = -std::numeric_limits<double>::infinity();  // abs min
  double last_off = -std::numeric_limits<double>::infinity();
  for (DayPlan& plan : days) {
    const double base = plan.day * 1440.0;
    const double off_before = base + plan.power_on_min() - last_off;
    bool first = true;
    for (const ScheduleEvent& e : plan.events) {
      if (e.kind == EventKind::kCut) {
        Job& job = plan.jobs[e.job];
        job.pause_before_min = base + e.start_min - last_heat_end;
        if (first && off_before >= 8 * 60) job.start_type = StartType::kCold;
        else if (job.pause_before_min <= 45) job.start_type = StartType::kWarm;
        else if (job.pause_before_min <= 180) job.start_type = StartType::kInterrupted;
        else job.start_type = StartType::kLongPause;
        first = false;
      }
      if (e.kind == EventKind::kCut || e.kind == EventKind::kLaserCycle) last_heat_end = base + e.end_min;
      if (e.kind == EventKind::kWarmupIdle) last_heat_end = base + e.end_min;
    }
    last_off = base + plan.power_off_min();
  }
}

}  // namespace whirl::machine
