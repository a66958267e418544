#include "machine/timeline.h"

#include <algorithm>
#include <cmath>
#include <map>

#include "core/error.h"
#include "core/numbers.h"
#include "core/random.h"
#include "machine/timeline_data.h"
#include "sim/physics.h"

namespace whirl::machine {

namespace {


// Axis position and speed within an event at clock c.
void AxisIn(const ScheduleEvent& e, const DayPlan& plan, double c, DutyState& d, double rapid) {
  const double dt = c - e.start_min;
  if (e.kind == EventKind::kCut) {
    const double v = plan.jobs[e.job].kinematics.axial_feed_mm_min;
    d.z_position_mm = e.z_from_mm - v * dt;
    d.z_speed_mm_min = v;
  } else if (e.kind == EventKind::kLaserCycle && e.feed_mm_min > 0) {
    const double span = std::abs(e.z_to_mm - e.z_from_mm);
    const double s = std::fmod(e.feed_mm_min * dt, 2 * span);
    d.z_position_mm = e.z_from_mm + (s < span ? s : 2 * span - s);
    d.z_speed_mm_min = e.feed_mm_min;
  } else {
    const double travel = std::abs(e.z_to_mm - e.z_from_mm) / rapid;
    const bool moving = dt < travel;
    d.z_position_mm = moving ? e.z_from_mm + (e.z_to_mm - e.z_from_mm) * dt / travel : e.z_to_mm;
    d.z_speed_mm_min = moving ? rapid : 0;
  }
}

DutyState DutyAt(const DayPlan& plan, double clock) {
  DutyState d;
  if (plan.events.empty() || clock < plan.power_on_min() || clock >= plan.power_off_min()) {
    if (!plan.events.empty())
      d.z_position_mm = clock < plan.power_on_min() ? plan.events.front().z_from_mm
                                                    : plan.events.back().z_to_mm;
    return d;
  }
  d.power_on = true;
  d.z_position_mm = plan.events.front().z_from_mm;
  constexpr double kRapid = 10000;
  for (const ScheduleEvent& e : plan.events) {
    if (e.end_min <= clock) {
      d.z_position_mm = e.z_to_mm;
      continue;
    }
    if (e.start_min > clock) break;
    AxisIn(e, plan, clock, d, kRapid);
    d.ring_on = e.kind == EventKind::kCut || e.kind == EventKind::kWarmupIdle;
    d.cutting = e.kind == EventKind::kCut;
    d.ring_rpm = d.ring_on ? e.ring_rpm : 0;
    d.job = e.job;
    break;
  }
  return d;
}

// Heat sources of the duty state (W per node; the nut's own share returned apart).
Eigen::VectorXd Sources(const FieldMachine& m, const DayPlan& plan, DutyState& d, double* nut_w) {
  const FieldMachineConfig& c = m.config();
  const HeadParams& h = c.head;
  Eigen::VectorXd q = Eigen::VectorXd::Zero(m.network().nodes());
  *nut_w = 0;
  d.drive_power_w = 0;
  if (!d.power_on) return q;
  if (d.ring_on) {
    const double r = d.ring_rpm / h.ref_ring_rpm;
    q(0) += h.bearing_power * std::pow(r, 5.0 / 3.0);
    q(1) += h.motor_power * std::pow(r, 1.5);
    q(2) += h.belt_power * r;
    d.drive_power_w = q(0) + q(1) + q(2);
  }
  if (d.cutting && d.job >= 0) {
    const double p = plan.jobs[d.job].cutting_power_w * plan.power_factor;
    q(0) += h.tool_heat_share * p;
    q(1) += h.motor_cut_share * p;
    const int bed0 = 7 + c.z.screw_cells;
    q(bed0 + m.BedCellAt(d.z_position_mm)) += c.bed.chip_share * p;
    q(bed0) += c.bed.headstock_power;
    d.drive_power_w += p;
  }
  const double omega = 2 * kPi * d.z_speed_mm_min / c.z.screw_lead_mm / 60;  // rad/s
  q(5) += c.z.motor_hold_power + c.z.motor_power_per_100mm_min * d.z_speed_mm_min / 100;
  q(6) += c.z.bearing_torque_nm * omega;
  const double nut = c.z.nut_torque_nm * omega;
  q(7 + m.ScrewCellAt(d.z_position_mm)) += 0.5 * nut;
  *nut_w = 0.5 * nut;
  return q;
}

struct Stepper {
  detail::TimelineData& data;
  std::map<long long, Propagator> cache;
  Eigen::VectorXd t_c, y;
  double nut = 20, now = 0;

  const Propagator& For(double dt_s) {
    const long long key = std::llround(dt_s * 1000);
    auto it = cache.find(key);
    if (it == cache.end()) it = cache.emplace(key, Propagator(data.machine.network(), dt_s)).first;
    return it->second;
  }
  double HallAt(double t) const {
    return data.hall.At(t) + (t >= 0 ? data.options.test_window_hall_offset_k : 0.0);
  }
  // Keeps the state at `now`, then steps by dt_s with the inputs of `now` held.
  void Step(const DayPlan* plan, double dt_s) {
    const FieldMachineConfig& c = data.machine.config();
    DutyState d = plan ? DutyAt(*plan, now - plan->day * 1440.0) : DutyState{};
    double nut_w = 0;
    Eigen::VectorXd q = plan ? Sources(data.machine, *plan, d, &nut_w)
                             : Eigen::VectorXd::Zero(t_c.size());
    if (now >= 0) q *= data.options.test_window_power_factor, nut_w *= data.options.test_window_power_factor;
    const double hall = HallAt(now), cabinet = c.cabinet_base_c + c.cabinet_hall_gain * (hall - 20);
    Keep(d, hall, cabinet);
    if (dt_s <= 0) return;
    const std::vector<DrawnSensor>& sensors = data.machine.sensors();
    for (std::size_t i = 0; i < sensors.size(); ++i) {
      const double loc = detail::LocationC(data, sensors[i], static_cast<int>(data.abs_min.size()) - 1);
      y(i) = loc + (y(i) - loc) * std::exp(-dt_s / (60 * sensors[i].spec.tau_min));
    }
    const double g = c.z.nut_screw + c.z.nut_air;
    const double cell = t_c(7 + data.machine.ScrewCellAt(d.z_position_mm));
    const double target = (c.z.nut_screw * cell + c.z.nut_air * hall + nut_w) / g;
    nut = target + (nut - target) * std::exp(-g * dt_s / c.z.nut_capacity);
    t_c = For(dt_s).Step(t_c, Eigen::Vector2d(hall, cabinet), q);
    now += dt_s / 60;
  }
  void Keep(const DutyState& d, double hall, double cabinet) {
    if (!data.abs_min.empty() && std::abs(data.abs_min.back() - now) < 1e-9) {
      data.abs_min.pop_back(), data.temps.pop_back(), data.nut_c.pop_back();
      data.hall_c.pop_back(), data.cabinet_c.pop_back(), data.duty.pop_back(), data.lagged.pop_back();
    }
    data.abs_min.push_back(now);
    data.temps.push_back(t_c);
    data.nut_c.push_back(nut);
    data.hall_c.push_back(hall);
    data.cabinet_c.push_back(cabinet);
    data.duty.push_back(d);
    data.lagged.push_back(y);
  }
  // Off time until abs_end on the night grid (the last step shorter).
  void Off(double abs_end) {
    const double step = data.options.night_step_s / 60;
    while (now < abs_end - 1e-9) Step(nullptr, 60 * std::min(step, abs_end - now));
  }
  void On(const DayPlan& plan) {
    const double end = plan.day * 1440.0 + plan.power_off_min();
    const double step = data.options.control_sample_s / 60;
    while (now < end - 1e-9) Step(&plan, 60 * std::min(step, end - now));
  }
};

}  // namespace

int detail::TimelineData::Locate(double t) const {
  const auto it = std::upper_bound(abs_min.begin(), abs_min.end(), t + 1e-9);
  return std::max(0, static_cast<int>(it - abs_min.begin()) - 1);
}

detail::TimelineData::Parts detail::TimelineData::ErrorAt(double t, double z_mm) const {
  const int k = Locate(t);
  Eigen::VectorXd temp = temps[k];
  if (k + 1 < static_cast<int>(abs_min.size()) && t > abs_min[k]) {
    const double w = std::min(1.0, (t - abs_min[k]) / (abs_min[k + 1] - abs_min[k]));
    temp = (1 - w) * temps[k] + w * temps[k + 1];
  }
  const ErrorParts p = machine.Error(temp, z_mm);
  const double extra = options.extra_error_um ? options.extra_error_um(t, z_mm) : 0.0;
  return {p.head_um, p.z_um, extra};
}

double detail::BlankTauMin(const TimelineData& d, const DayPlan& plan, int job) {
  const FieldMachineConfig& c = d.machine.config();
  if (!(c.blank_h_w_m2k > 0)) return c.blank_tau_min;
  const double diameter_m =
      plan.jobs[static_cast<std::size_t>(job)].screw.process.diameter_mm / 1000.0;
  return c.steel_density * c.steel_heat * diameter_m / (4 * c.blank_h_w_m2k) / 60.0;
}

double detail::CutBlankC(const TimelineData& d, const DayPlan& plan, int job) {
  return BlankAtC(d, plan, job,
                  plan.day * 1440.0 + plan.jobs[static_cast<std::size_t>(job)].cut_start_min);
}

double detail::BlankAtC(const TimelineData& d, const DayPlan& plan, int job, double abs_min) {
  double c = BlankTemperatureC(d, abs_min, BlankTauMin(d, plan, job));
  const double sd = d.machine.config().stock_offset_std_k;
  if (sd > 0) {
    Rng rng(MixSeed(plan.seed, 0x73746f636bULL + static_cast<std::uint64_t>(job)));
    c += sd * rng.Normal();
  }
  return c;
}

double detail::BlankTemperatureC(const TimelineData& d, double abs_min, double tau_min) {
  const double tau = tau_min, step = tau / 20;
  double sum = 0, weight = 0;
  for (int i = 0; i < 160; ++i) {  // 8 tau, midpoint rule
    const double age = (i + 0.5) * step, w = std::exp(-age / tau);
    const double t = abs_min - age;
    sum += w * (d.hall.At(t) + (t >= 0 ? d.options.test_window_hall_offset_k : 0.0));
    weight += w;
  }
  return sum / weight;
}

double detail::BlankReferenceUm(double blank_start_c, double z_mm) {
  return 1e3 * sim::PhysicsConstants{}.expansion_per_k * (blank_start_c - 20) * z_mm;
}

double detail::LocationC(const TimelineData& d, const DrawnSensor& s, int k) {
  const Eigen::VectorXd& t = d.temps[k];
  if (s.spec.kind == "bed") return s.bed_weight * t(s.bed_a) + (1 - s.bed_weight) * t(s.bed_b);
  if (s.spec.kind == "boundary") return s.index_a == -2 ? d.hall_c[k] : d.cabinet_c[k];
  const double a = s.index_a == kNutSensorIndex ? d.nut_c[k] : t(s.index_a);
  if (s.spec.kind == "pair") return s.spec.weight * a + (1 - s.spec.weight) * t(s.index_b);
  return a;
}

MachineTimeline SimulateCalendar(const FieldMachine& machine, const HallProfile& hall,
                                 std::vector<DayPlan> days, const TimelineOptions& options) {
  if (days.empty()) throw InputError("timeline: no days");
  if (!(options.control_sample_s >= 1 && options.control_sample_s <= 60))
    throw InputError("timeline: control sample must be 1-60 s, got " +
                     std::to_string(options.control_sample_s));
  ClassifyStarts(days);
  if (days.front().day < hall.first_day() || days.back().day > hall.last_day())
    throw InputError("timeline: the hall profile does not cover the calendar");
  auto data = std::make_shared<detail::TimelineData>(
      detail::TimelineData{machine, hall, days, options, {}, {}, {}, {}, {}, {}, {}});
  Stepper st{*data, {}, {}, {}};
  st.now = days.front().day * 1440.0;
  const double hall0 = hall.At(st.now);
  const FieldMachineConfig& c = machine.config();
  st.t_c = machine.network().SteadyState(
      Eigen::Vector2d(hall0, c.cabinet_base_c + c.cabinet_hall_gain * (hall0 - 20)),
      Eigen::VectorXd::Zero(machine.network().nodes()));
  st.nut = hall0;
  st.y = Eigen::VectorXd::Constant(machine.sensors().size(), hall0);
  data->abs_min.push_back(st.now);  // provisional state for the sensors' first location
  data->temps.push_back(st.t_c);
  data->nut_c.push_back(hall0), data->hall_c.push_back(hall0);
  data->cabinet_c.push_back(c.cabinet_base_c + c.cabinet_hall_gain * (hall0 - 20));
  data->duty.push_back({}), data->lagged.push_back(st.y);
  for (std::size_t i = 0; i < machine.sensors().size(); ++i)
    st.y(i) = detail::LocationC(*data, machine.sensors()[i], 0);
  for (const DayPlan& plan : data->days) {
    st.Off(plan.day * 1440.0 + plan.power_on_min());
    st.On(plan);
  }
  st.Off((data->days.back().day + 1) * 1440.0);
  st.Step(nullptr, 0);
  MachineTimeline timeline;
  timeline.data_ = data;
  return timeline;
}

const std::vector<DayPlan>& MachineTimeline::days() const { return data_->days; }
const FieldMachine& MachineTimeline::machine() const { return data_->machine; }
const HallProfile& MachineTimeline::hall() const { return data_->hall; }
const TimelineOptions& MachineTimeline::options() const { return data_->options; }

const DayPlan& MachineTimeline::Day(int day) const {
  for (const DayPlan& p : data_->days)
    if (p.day == day) return p;
  throw InputError("timeline: day " + std::to_string(day) + " is not in the calendar");
}

DutyState MachineTimeline::Duty(double abs_min) const {
  return data_->duty[data_->Locate(abs_min)];
}

}  // namespace whirl::machine
