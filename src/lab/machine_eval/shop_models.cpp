#include "machine_eval/history.h"

#include <cmath>
#include <optional>

#include "core/error.h"
#include "core/random.h"

namespace whirl::machine_eval {

drift::Run ControlDayLog(const drift::Run& run, double cutting_speed_m_min) {
  drift::Run log = run;
  log.error_names.clear();
  log.error_um.resize(run.samples(), 0);
  const bool cutting = run.state == drift::RunState::kCutting;
  log.other_names = {"power_on", "ring_on", "cutting", "ring_load_pct"};
  log.other.resize(run.samples(), 4);
  const double load = 20.0 + (cutting ? 60.0 * cutting_speed_m_min / 180.0 : 0.0);
  for (int k = 0; k < run.samples(); ++k) {
    const double on = k == 0 ? 0.0 : 1.0;
    log.other.row(k) << on, on, cutting ? on : 0.0, on * load;
  }
  return log;
}

namespace {

// The run's true m(t, z) at sample k (the instrument's reading before its noise).
double TrueAt(const drift::Run& run, int k, double z_mm, double z_fixed_mm) {
  return run.error_um(k, run.ErrorIndex("offset_um")) +
         run.error_um(k, run.ErrorIndex("zscrew_per_1000_um")) * (z_fixed_mm - z_mm) / 1000.0;
}

drift::MeasurementRecord Readings(const drift::Run& run, int log, double every_min, double z_mm,
                                  double sigma_um, double z_fixed_mm, const ShopProtocol& p,
                                  Rng* rng) {
  drift::MeasurementRecord r;
  r.day = log;
  r.log = log;
  const double zero = p.record_zero_std_um * rng->Normal();
  double next = 0;
  for (int k = 0; k < run.samples(); ++k) {
    if (run.time_min[k] + 1e-9 < next) continue;
    next += every_min;
    r.rows.push_back({k, run.time_min[k], z_mm,
                      TrueAt(run, k, z_mm, z_fixed_mm) + zero + sigma_um * rng->Normal(),
                      sigma_um});
  }
  return r;
}

}  // namespace

drift::ShopRecord MeasureTrainingRuns(const std::vector<drift::Run>& runs,
                                      const std::vector<double>& speeds, double z_fixed_mm,
                                      const ShopProtocol& p, std::uint64_t seed) {
  drift::ShopRecord rec;
  for (std::size_t i = 0; i < runs.size(); ++i) {
    const drift::Run& run = runs[i];
    const int log = static_cast<int>(i);
    Rng rng(MixSeed(seed, 0x50524f42 + i));
    rec.day_logs.push_back(ControlDayLog(run, speeds[i]));
    drift::MeasurementRecord probe =
        Readings(run, log, p.probe_every_min, p.probe_z_mm, p.probe_sigma_um, z_fixed_mm, p, &rng);
    probe.kind = drift::MeasurementRecord::Kind::kProbe;
    probe.name = run.name + "_probe";
    rec.records.push_back(probe);
    if (run.state != drift::RunState::kIdle) continue;
    for (double z : p.laser_targets_mm) {
      const double sigma = p.laser_noise_um + p.laser_noise_ppm * 1e-3 * z;
      drift::MeasurementRecord laser =
          Readings(run, log, p.laser_every_min, z, sigma, z_fixed_mm, p, &rng);
      laser.kind = drift::MeasurementRecord::Kind::kLaser;
      laser.name = run.name + "_laser_" + std::to_string(static_cast<int>(z));
      rec.records.push_back(laser);
    }
  }
  return rec;
}

ShopModels FitShopModels(const drift::ShopRecord& record, double z_fixed_mm,
                         const std::vector<std::string>& schedule_inputs) {
  ShopModels m;
  drift::JointFitOptions lagged;
  lagged.require_lag = true;
  drift::JointSpec warmup;
  warmup.z_ref_mm = z_fixed_mm;
  warmup.other_inputs = {"power_on"};
  m.warmup = drift::FitJoint(record, warmup, lagged).model;
  drift::JointSpec schedule;
  schedule.z_ref_mm = z_fixed_mm;
  schedule.other_inputs = schedule_inputs;
  m.schedule = drift::FitJoint(record, schedule, lagged).model;
  const bool schedule_base = m.schedule.cv_rmse_um <= m.warmup.cv_rmse_um;
  const drift::JointDriftModel& base = schedule_base ? m.schedule : m.warmup;
  std::vector<std::string> pool;
  for (const auto& name : record.day_logs.front().sensor_names) pool.push_back(name);
  drift::JointSpec alone;
  alone.z_ref_mm = z_fixed_mm;
  alone.sensor_pool = pool;
  // No sensor lowers the CV below the constant: the candidate does not exist (the record itself
  // passed the fits above, so this is the only InputError left).
  std::optional<drift::JointDriftModel> sensors;
  try {
    sensors = drift::FitJoint(record, alone, {}).model;
  } catch (const InputError&) {
  }
  // Sensors on top of the sensor-free rule: its inputs and lags, a sensor added only while the
  // grouped CV falls.
  drift::JointSpec on_top = alone;
  on_top.other_inputs = base.other_inputs;
  on_top.time_constants = base.time_constants;
  drift::JointFitOptions keep_lags;
  keep_lags.max_lags = static_cast<int>(base.time_constants.size());
  const drift::JointDriftModel combined = drift::FitJoint(record, on_top, keep_lags).model;
  const std::string base_name = schedule_base ? "schedule" : "warmup";
  m.sensors = base;
  m.sensors_choice = base_name;
  if (sensors && sensors->cv_rmse_um < m.sensors.cv_rmse_um)
    m.sensors = *sensors, m.sensors_choice = "sensors";
  if (combined.cv_rmse_um < m.sensors.cv_rmse_um)
    m.sensors = combined, m.sensors_choice = "sensors+" + base_name;
  return m;
}

}  // namespace whirl::machine_eval
