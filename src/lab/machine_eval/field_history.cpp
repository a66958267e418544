#include "machine_eval/field_history.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/random.h"

namespace whirl::machine_eval {

namespace {

using Kind = drift::MeasurementRecord::Kind;

// Row of the log at or last before time t (the log's first row is the day's power-on).
int SampleAt(const drift::Run& log, double t_min) {
  const auto it = std::upper_bound(log.time_min.begin(), log.time_min.end(), t_min + 1e-9);
  return it == log.time_min.begin() ? 0 : static_cast<int>(it - log.time_min.begin()) - 1;
}

drift::MeasurementRecord RecordOf(Kind kind, const machine::DayPlan& plan, int log_index,
                                  const std::string& name, const drift::Run& log,
                                  const std::vector<machine::Reading>& readings, double sigma) {
  drift::MeasurementRecord r;
  r.kind = kind;
  r.day = plan.day;
  r.log = log_index;
  r.name = "day" + std::to_string(plan.day) + "_" + name;
  for (const machine::Reading& x : readings)
    r.rows.push_back({SampleAt(log, x.abs_min), x.abs_min, x.z_mm, x.value_um,
                      sigma > 0 ? sigma : x.sigma_um});
  return r;
}

// Times from power-on every `every` min, before power-off.
std::vector<double> Every(const machine::DayPlan& plan, double every) {
  std::vector<double> t;
  const double base = plan.day * 1440.0;
  for (double c = plan.power_on_min(); c < plan.power_off_min() - 1e-9; c += every)
    t.push_back(base + c);
  return t;
}

void WarmupTest(const machine::MachineTimeline& tl, const machine::DayPlan& plan, int log,
                const drift::Run& day_log, const FieldProtocol& p, std::uint64_t seed,
                drift::ShopRecord* rec) {
  const auto r = machine::ProbeReadings(tl, Every(plan, p.check_every_min), p.probe_z_mm,
                                        p.probe_sigma_um, seed);
  rec->records.push_back(RecordOf(Kind::kProbe, plan, log, "warmup_probe", day_log, r, 0));
}

void LaserTest(const machine::MachineTimeline& tl, const machine::DayPlan& plan, int log,
               const drift::Run& day_log, const FieldProtocol& p, std::uint64_t seed,
               drift::ShopRecord* rec) {
  const std::vector<double> times = Every(plan, p.laser_every_min);
  const auto r = machine::LaserReadings(tl, times, p.laser_targets_mm, p.laser_noise_um,
                                        p.laser_noise_ppm, seed);
  for (std::size_t i = 0; i < p.laser_targets_mm.size(); ++i) {
    const std::vector<machine::Reading> one(r.begin() + i * times.size(),
                                            r.begin() + (i + 1) * times.size());
    rec->records.push_back(RecordOf(Kind::kLaser, plan, log,
                                    "laser_" + std::to_string(static_cast<int>(p.laser_targets_mm[i])),
                                    day_log, one, 0));
  }
}

// A past screw's measured lead, thinned to one point per lead_sample_min of cutting time; the
// reading's z becomes the tool position (thread start - x).
// Least-squares slope of the readings' values over their x (z_mm holds x), um per m.
double SlopeUmPerM(const std::vector<machine::Reading>& r) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = static_cast<double>(r.size());
  for (const auto& x : r) sx += x.z_mm, sy += x.value_um, sxx += x.z_mm * x.z_mm, sxy += x.z_mm * x.value_um;
  const double d = n * sxx - sx * sx;
  return d > 0 ? 1000.0 * (n * sxy - sx * sy) / d : 0.0;
}

void PastLead(const machine::MachineTimeline& tl, const machine::DayPlan& plan, int log,
              const drift::Run& day_log, int job, const FieldProtocol& p,
              const WorkpieceResidual& residual, std::uint64_t seed, drift::ShopRecord* rec,
              std::vector<PastLeadSlope>* slopes) {
  const machine::Job& j = plan.jobs[static_cast<std::size_t>(job)];
  const machine::CutRef cut{plan.day, job};
  const std::function<double(double)> wp = residual ? residual(j, cut) : nullptr;
  if (residual && !wp) return;
  machine::LeadOptions lo;
  lo.step_mm = p.lead_step_mm;
  lo.noise_um = p.lead_noise_um;
  lo.scale_noise_um_per_m = p.lead_scale_noise_um_per_m;
  const auto all = machine::MeasureLead(
      tl, cut, wp ? wp : [](double) { return 0.0; }, lo, seed);
  if (slopes && all.size() > 1)
    slopes->push_back({j.screw.process.diameter_mm, j.screw.process.pitch_mm, SlopeUmPerM(all)});
  std::vector<machine::Reading> kept;
  double next = all.empty() ? 0 : all.front().abs_min;
  for (machine::Reading x : all) {
    if (x.abs_min + 1e-9 < next) continue;
    next += p.lead_sample_min;
    x.z_mm = j.kinematics.thread_start_position_mm - x.z_mm;
    kept.push_back(x);
  }
  rec->records.push_back(RecordOf(Kind::kLead, plan, log, "lead_" + std::to_string(job), day_log,
                                  kept, p.lead_sigma_um));
}

// The probe at power-on and at the start of every set-up of a production day.
void SetupChecks(const machine::MachineTimeline& tl, const machine::DayPlan& plan, int log,
                 const drift::Run& day_log, const FieldProtocol& p, std::uint64_t seed,
                 drift::ShopRecord* rec) {
  const std::vector<double> t = SetupCheckTimes(plan);
  if (t.size() < 2) return;
  const auto r = machine::ProbeReadings(tl, t, p.probe_z_mm, p.probe_sigma_um, seed);
  rec->records.push_back(RecordOf(Kind::kSetupCheck, plan, log, "setup_checks", day_log, r, 0));
}

}  // namespace

std::vector<double> SetupCheckTimes(const machine::DayPlan& plan) {
  std::vector<double> t = {plan.day * 1440.0 + plan.power_on_min()};
  for (const machine::ScheduleEvent& e : plan.events)
    if (e.kind == machine::EventKind::kSetup && e.start_min > plan.power_on_min() + 1e-9)
      t.push_back(plan.day * 1440.0 + e.start_min);
  return t;
}

double LeadSlopeFor(const std::vector<PastLeadSlope>& past, double diameter_mm, double lead_mm,
                    int k) {
  if (past.empty()) return 0.0;
  std::vector<std::pair<double, std::size_t>> d;
  for (std::size_t i = 0; i < past.size(); ++i) {
    const double a = std::log(past[i].diameter_mm / diameter_mm);
    const double b = std::log(past[i].lead_mm / lead_mm);
    d.push_back({a * a + b * b, i});
  }
  std::stable_sort(d.begin(), d.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  const std::size_t n = std::min(d.size(), static_cast<std::size_t>(std::max(k, 1)));
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += past[d[i].second].slope_um_per_m;
  return sum / static_cast<double>(n);
}

drift::Run AverageSensors(drift::Run log, double window_min) {
  if (window_min <= 0 || log.samples() == 0) return log;
  const Eigen::MatrixXd raw = log.temperature_C;
  Eigen::RowVectorXd sum = Eigen::RowVectorXd::Zero(raw.cols());
  int first = 0;
  for (int k = 0; k < log.samples(); ++k) {
    sum += raw.row(k);
    while (log.time_min[static_cast<std::size_t>(first)] <=
           log.time_min[static_cast<std::size_t>(k)] - window_min + 1e-9)
      sum -= raw.row(first++);
    log.temperature_C.row(k) = sum / static_cast<double>(k - first + 1);
  }
  return log;
}

drift::ShopRecord FieldShopRecord(const machine::MachineTimeline& timeline,
                                  const FieldProtocol& p,
                                  const WorkpieceResidual& workpiece_residual, std::uint64_t seed,
                                  std::vector<PastLeadSlope>* lead_slopes) {
  drift::ShopRecord rec;
  machine::LogOptions lo;
  lo.sample_s = p.log_sample_s;
  for (const machine::DayPlan& plan : timeline.days()) {
    if (plan.day >= 0) continue;  // the test window is never read
    const std::uint64_t s = MixSeed(seed, plan.seed);
    const int log = static_cast<int>(rec.day_logs.size());
    rec.day_logs.push_back(AverageSensors(machine::DayLog(timeline, plan.day, lo, MixSeed(s, 1)),
                                          p.sensor_average_min));
    const drift::Run& day_log = rec.day_logs.back();
    switch (plan.role) {
      case machine::DayRole::kWarmupTest:
        WarmupTest(timeline, plan, log, day_log, p, MixSeed(s, 2), &rec);
        break;
      case machine::DayRole::kLaserTest:
        LaserTest(timeline, plan, log, day_log, p, MixSeed(s, 3), &rec);
        break;
      default:
        for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j)
          PastLead(timeline, plan, log, rec.day_logs.back(), j, p, workpiece_residual,
                   MixSeed(s, 100 + j), &rec, lead_slopes);
        if (p.setup_checks) SetupChecks(timeline, plan, log, day_log, p, MixSeed(s, 4), &rec);
    }
  }
  return rec;
}

}  // namespace whirl::machine_eval
