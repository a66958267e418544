#include "machine/instruments.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/random.h"
#include "machine/timeline_data.h"

namespace whirl::machine {

namespace {

constexpr double kZeroStdUm = 50;  // an instrument's unknown zero per record
const char* const kDutyColumns[] = {"power_on",       "ring_on",       "ring_rpm",
                                    "ring_load_pct",  "cutting",       "z_speed_mm_min",
                                    "z_position_mm",  "clock_min"};

Eigen::RowVectorXd DutyRow(const DutyState& d, double rated_w, double clock, double load_noise) {
  Eigen::RowVectorXd row(8);
  row << (d.power_on ? 1.0 : 0.0), (d.ring_on ? 1.0 : 0.0), d.ring_rpm,
      100.0 * d.drive_power_w / rated_w + (d.ring_on ? load_noise : 0.0), (d.cutting ? 1.0 : 0.0),
      d.z_speed_mm_min, d.z_position_mm, clock;
  return row;
}

// blank_contact_C of a day's rows (FieldMachineConfig::blank_contact_std_k): each job's blank read
// at its clamping (its set-up's start; the cut start without a set-up), held until the next one.
Eigen::VectorXd BlankContactColumn(const detail::TimelineData& data, const DayPlan& plan,
                                   const std::vector<double>& abs_min) {
  const double sd = data.machine.config().blank_contact_std_k;
  std::vector<std::pair<double, double>> readings;  // (abs min, degC)
  for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
    double clamp = plan.jobs[static_cast<std::size_t>(j)].cut_start_min;
    for (const ScheduleEvent& e : plan.events)
      if (e.kind == EventKind::kSetup && e.job == j) clamp = std::min(clamp, e.start_min);
    clamp += plan.day * 1440.0;
    Rng rng(MixSeed(plan.seed, 0x636f6e74616374ULL + static_cast<std::uint64_t>(j)));
    readings.push_back({clamp, detail::BlankAtC(data, plan, j, clamp) + sd * rng.Normal()});
  }
  Eigen::VectorXd col = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(abs_min.size()), 20.0);
  for (std::size_t r = 0; r < abs_min.size(); ++r)
    for (const auto& [t, c] : readings)
      if (t <= abs_min[r] + 1e-9) col(static_cast<Eigen::Index>(r)) = c;
  return col;
}

}  // namespace

drift::Run DayLog(const MachineTimeline& timeline, int day, const LogOptions& options,
                  std::uint64_t seed) {
  const detail::TimelineData& data = timeline.data();
  const DayPlan& plan = timeline.Day(day);
  const double ratio = options.sample_s / data.options.control_sample_s;
  const int stride = static_cast<int>(std::lround(ratio));
  if (stride < 1 || std::abs(ratio - stride) > 1e-9)
    throw InputError("sensor log: sample " + std::to_string(options.sample_s) +
                     " s must be a multiple of the control sample " +
                     std::to_string(data.options.control_sample_s) + " s");
  const double on = day * 1440.0 + plan.power_on_min(), off = day * 1440.0 + plan.power_off_min();
  std::vector<int> rows;
  for (int k = data.Locate(on); k < static_cast<int>(data.abs_min.size()) && data.abs_min[k] < off - 1e-9; k += stride)
    rows.push_back(k);
  const auto& sensors = data.machine.sensors();
  drift::Run run;
  run.name = "day" + std::to_string(day);
  run.source = run.name;
  run.state = drift::RunState::kUnknown;
  if (options.sensors)
    for (const DrawnSensor& s : sensors) run.sensor_names.push_back(s.spec.name + "_C");
  if (options.duty) run.other_names.assign(std::begin(kDutyColumns), std::end(kDutyColumns));
  run.temperature_C.resize(rows.size(), run.sensor_names.size());
  run.other.resize(rows.size(), run.other_names.size());
  Rng rng(seed);
  const double rated_w = 1000 * data.machine.config().head.rated_drive_kw;
  for (std::size_t r = 0; r < rows.size(); ++r) {
    const int k = rows[r];
    run.time_min.push_back(data.abs_min[k]);
    run.line_numbers.push_back(static_cast<int>(r) + 2);
    if (options.sensors)
      for (std::size_t i = 0; i < sensors.size(); ++i)
        run.temperature_C(r, i) = ReadSensor(sensors[i], data.machine.config().noise,
                                             data.lagged[k](i), rng.Normal());
    if (options.duty) {
      const DutyState d = r == 0 ? DutyState{} : data.duty[k];
      const double noise = options.load_noise_pct * rng.Normal();
      run.other.row(r) = DutyRow(d, rated_w, data.abs_min[k] - day * 1440.0, noise);
      if (r == 0) run.other(r, 6) = data.duty[k].z_position_mm;
    }
  }
  if (options.sensors && data.machine.config().blank_contact_std_k >= 0) {
    run.sensor_names.push_back("blank_contact_C");
    run.temperature_C.conservativeResize(Eigen::NoChange, run.temperature_C.cols() + 1);
    run.temperature_C.col(run.temperature_C.cols() - 1) =
        BlankContactColumn(data, plan, run.time_min);
  }
  return run;
}

drift::Run ControlLog(const MachineTimeline& timeline, int day, std::uint64_t seed) {
  LogOptions options;
  options.sample_s = timeline.options().control_sample_s;
  return DayLog(timeline, day, options, seed);
}

drift::Run CheckRingLog(const MachineTimeline& timeline, int day, double sample_s, double z_mm,
                        double sigma_um, std::uint64_t seed) {
  LogOptions options;
  options.sample_s = sample_s;
  drift::Run run = DayLog(timeline, day, options, MixSeed(seed, 0x6c6f67));
  const std::vector<Reading> r =
      ProbeReadings(timeline, run.time_min, z_mm, sigma_um, MixSeed(seed, 0x70726f));
  run.error_names = {"offset_um"};
  run.error_um.resize(run.samples(), 1);
  for (int k = 0; k < run.samples(); ++k)
    run.error_um(k, 0) = r[static_cast<std::size_t>(k)].value_um - r.front().value_um;
  for (double& t : run.time_min) t -= day * 1440.0;  // minutes since the day's 00:00
  return run;
}

std::vector<Reading> ProbeReadings(const MachineTimeline& timeline,
                                   const std::vector<double>& abs_min, double z_mm,
                                   double sigma_um, std::uint64_t seed) {
  Rng rng(seed);
  const double zero = kZeroStdUm * rng.Normal();
  std::vector<Reading> out;
  for (double t : abs_min) {
    const auto p = timeline.data().ErrorAt(t, z_mm);
    out.push_back({t, z_mm, p.head_um + p.z_um + p.extra_um + zero + sigma_um * rng.Normal(),
                   sigma_um});
  }
  return out;
}

std::vector<Reading> LaserReadings(const MachineTimeline& timeline,
                                   const std::vector<double>& abs_min,
                                   const std::vector<double>& targets_mm, double noise_um,
                                   double noise_ppm, std::uint64_t seed) {
  Rng rng(seed);
  std::vector<Reading> out;
  for (double z : targets_mm) {
    const double zero = kZeroStdUm * rng.Normal();
    const double sigma = noise_um + noise_ppm * 1e-3 * std::abs(z);  // 1 ppm of 1 mm = 1e-3 um
    for (double t : abs_min) {
      const auto p = timeline.data().ErrorAt(t, z);
      out.push_back({t, z, p.z_um + p.extra_um + zero + sigma * rng.Normal(), sigma});
    }
  }
  return out;
}

std::vector<Reading> MeasureLead(const MachineTimeline& timeline, const CutRef& cut,
                                 const std::function<double(double t_s)>& workpiece_minus_comp_um,
                                 const LeadOptions& options, std::uint64_t seed) {
  const DayPlan& plan = timeline.Day(cut.day);
  if (cut.job < 0 || cut.job >= static_cast<int>(plan.jobs.size()))
    throw InputError("lead measurement: day " + std::to_string(cut.day) + " has no job " +
                     std::to_string(cut.job));
  const Job& job = plan.jobs[cut.job];
  const screw::Kinematics& k = job.kinematics;
  const double start = cut.day * 1440.0 + job.cut_start_min;
  Rng rng(seed);
  const double scale = options.scale_noise_um_per_m * rng.Normal();
  const double blank_c = detail::CutBlankC(timeline.data(), plan, cut.job);
  auto total = [&](double x) {
    const double t_s = x / k.axial_feed_mm_s;
    const auto p = timeline.data().ErrorAt(start + t_s / 60, k.thread_start_position_mm - x);
    const double z = k.thread_start_position_mm - x;
    return p.head_um + p.z_um + p.extra_um + detail::BlankReferenceUm(blank_c, z) +
           workpiece_minus_comp_um(t_s);
  };
  const double at0 = total(0);
  std::vector<Reading> out;
  for (double x = 0; x <= job.screw.thread_length_mm + 1e-9; x += options.step_mm) {
    const double value = total(x) - at0 + options.noise_um * rng.Normal() + scale * x / 1000;
    out.push_back({start + x / k.axial_feed_mm_s / 60, x, value, options.noise_um});
  }
  return out;
}

}  // namespace whirl::machine
