#include "machine_eval/shop_models.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>
#include <utility>

#include "core/error.h"
#include "drift/monitor.h"
#include "machine_eval/machine_eval.h"

namespace whirl::machine_eval {

std::vector<std::string> ScheduleInputs() {
  return {"ring_on", "cutting", "ring_load_pct", "z_speed_mm_min"};
}

namespace {

// A sensor-free rule's spec: control signals as logged, at least one lag (RuleOptions).
drift::JointSpec RuleSpec(double z_ref_mm, std::vector<std::string> inputs) {
  drift::JointSpec s;
  s.z_ref_mm = z_ref_mm;
  s.other_inputs = std::move(inputs);
  return s;
}

drift::JointFitOptions RuleOptions() {
  drift::JointFitOptions o;
  o.require_lag = true;
  return o;
}

// The records of the days before `day` (every day log kept: records index them).
drift::ShopRecord Before(const drift::ShopRecord& record, int day) {
  drift::ShopRecord r;
  r.day_logs = record.day_logs;
  for (const drift::MeasurementRecord& m : record.records)
    if (m.day < day) r.records.push_back(m);
  return r;
}

// A lead record's residuals about their weighted mean (w = 1 / sigma^2: a lead is known up to a
// constant), each scaled by 1 / sigma (so a sum of squares is the weighted one), and the sum of w.
std::pair<std::vector<double>, double> Demeaned(const drift::MeasurementRecord& r,
                                                const std::vector<double>& predicted) {
  double sw = 0, swe = 0;
  for (std::size_t i = 0; i < r.rows.size(); ++i) {
    const double w = 1 / (r.rows[i].sigma_um * r.rows[i].sigma_um);
    sw += w, swe += w * (r.rows[i].value_um - predicted[i]);
  }
  std::vector<double> e(r.rows.size());
  for (std::size_t i = 0; i < r.rows.size(); ++i)
    e[i] = (r.rows[i].value_um - predicted[i] - swe / sw) / r.rows[i].sigma_um;
  return {std::move(e), sw};
}

// The pooled sums the guard and the combination weight need, over the scored lead records.
struct PooledResiduals {
  double grey_ss = 0, rule_ss = 0, sw = 0;
  double cross = 0, spread = 0;  ///< sum e_r (e_r - e_g), sum (e_r - e_g)^2
  void Add(const std::vector<double>& grey, const std::vector<double>& rule) {
    for (std::size_t i = 0; i < grey.size(); ++i) {
      const double d = rule[i] - grey[i];
      grey_ss += grey[i] * grey[i], rule_ss += rule[i] * rule[i];
      cross += rule[i] * d, spread += d * d;
    }
  }
};

}  // namespace

GuardScore GuardGreyBox(const drift::ShopRecord& record, const drift::GreyBoxSpec& grey,
                        const drift::GreyBoxOptions& grey_options, const drift::JointSpec& rule,
                        const drift::JointFitOptions& rule_options, int held_days) {
  const std::vector<int> lead_days = drift::LeadDays(record);
  if (held_days < 1)
    throw InputError("grey guard: held_days = " + std::to_string(held_days) + ": must be >= 1");
  const std::size_t held = static_cast<std::size_t>(held_days);
  const std::size_t first = lead_days.size() > held ? lead_days.size() - held : 0;
  PooledResiduals p;
  GuardScore g;
  for (std::size_t k = first; k < lead_days.size(); ++k) {
    const drift::ShopRecord past = Before(record, lead_days[k]);
    if (past.records.empty()) continue;
    drift::GreyBoxModel gm;
    drift::JointDriftModel rm;
    try {
      gm = drift::FitGreyBox(past, grey, grey_options);
      rm = drift::FitJoint(past, rule, rule_options).model;
    } catch (const InputError&) {
      continue;  // too few readings before this day: not scored
    }
    for (const drift::MeasurementRecord& r : record.records) {
      if (r.kind != drift::MeasurementRecord::Kind::kLead || r.day != lead_days[k]) continue;
      const auto [grey_e, w] = Demeaned(r, drift::PredictGreyRecord(gm, record, r));
      p.Add(grey_e, Demeaned(r, drift::PredictRecord(rm, record, r)).first);
      p.sw += w;
    }
    ++g.days;
  }
  if (g.days == 0 || p.sw <= 0) return g;
  g.grey_rms_um = std::sqrt(p.grey_ss / p.sw);
  g.rule_rms_um = std::sqrt(p.rule_ss / p.sw);
  g.keep_grey = g.grey_rms_um <= g.rule_rms_um;
  if (p.spread > 0) g.combination_weight = p.cross / p.spread;
  return g;
}

ShopModels::Mix ShortMixWeights(bool long_record, const GuardScore& guard) {
  if (long_record) return {};
  return {std::clamp(guard.combination_weight, kShortMixFloor, 1.0), kShortMixFixedWeight};
}

ShopModels FitShopModels(const drift::ShopRecord& record, double z_fixed_mm,
                         const std::vector<std::string>& schedule_inputs, bool grey_slope_lags_only,
                         bool grey_candidates, bool grey_five_sensors, bool grey_short_mix) {
  ShopModels m;
  const drift::JointFitOptions lagged = RuleOptions();
  const drift::JointSpec warmup = RuleSpec(z_fixed_mm, {"power_on"}),
                         schedule = RuleSpec(z_fixed_mm, schedule_inputs);
  m.warmup = drift::FitJoint(record, warmup, lagged).model;
  m.schedule = drift::FitJoint(record, schedule, lagged).model;
  const bool schedule_base = m.schedule.cv_rmse_um <= m.warmup.cv_rmse_um;
  m.rule_is_schedule = schedule_base;
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
  // The grey box needs the field machine's sensors (a record without them keeps it empty).
  const std::vector<std::string>& have = record.day_logs.front().sensor_names;
  const bool contact =
      std::find(have.begin(), have.end(), kBlankContactSensor) != have.end();
  const drift::GreyBoxSpec grey = FieldGreyBoxSpec(z_fixed_mm, contact);
  bool placed = true;
  for (const std::string& s : grey.Inputs())
    placed = placed && std::find(have.begin(), have.end(), s) != have.end();
  const std::vector<std::string>& other = record.day_logs.front().other_names;
  for (const std::string& s : grey.DutyInputs())
    placed = placed && std::find(other.begin(), other.end(), s) != other.end();
  if (!placed) return m;
  const drift::GreyBoxOptions grey_options = FieldGreyBoxOptions(contact, grey_slope_lags_only);
  // Every sensor once the record is long (the eleventh round's default), else the five.
  const GreyCandidateFit all = FieldGreyCandidate(z_fixed_mm, contact, have);
  const bool long_record = EverySensorByDays(record, grey_options);
  const bool every = long_record && !grey_five_sensors;
  const drift::GreyBoxSpec& applied = every ? all.spec : grey;  // both_grey's sensors
  m.grey = drift::FitGreyBox(record, applied, grey_options);
  if (!grey_candidates && !grey_short_mix) return m;
  // The guard scores the model it would apply: both_grey's (its sensors, its options); its
  // combination weight is the fourteenth round's mix.
  const GuardScore g =
      GuardGreyBox(record, applied, grey_options, schedule_base ? schedule : warmup, lagged);
  m.guard = {grey_candidates, g.keep_grey, g.grey_rms_um, g.rule_rms_um};
  m.mix = ShortMixWeights(long_record, g);
  m.mix.computed = true;
  m.mix.applied = grey_short_mix;
  if (!grey_candidates) return m;
  const bool same = every && !grey_slope_lags_only;  // then m.grey is grey_all_sensors' model
  m.grey_candidates.push_back(same ? m.grey : drift::FitGreyBox(record, all.spec, all.options));
  // A short record's m.grey is the five sensors' model, with or without grey_five_sensors.
  drift::GreyBoxModel by_days = long_record ? m.grey_candidates[0] : m.grey;
  m.grey_candidates.push_back(std::move(by_days));
  // The twelfth round's row: both_grey's model, the strength fixed at 1 on a short record (on a
  // long one the option does nothing: both_grey's model itself).
  m.grey_candidates.push_back(
      long_record ? m.grey
                  : drift::FitGreyBox(record, applied, ShortRecordStrongPrior(grey_options)));
  // The thirteenth round's rows: the offset sensors as read, or through the shortest lag.
  for (int lags : {0, 1})
    m.grey_candidates.push_back(
        long_record ? m.grey
                    : drift::FitGreyBox(record, applied, ShortRecordOffsetLags(grey_options, lags)));
  return m;
}

GreyCandidateFit FieldGreyCandidate(double z_ref_mm, bool blank_contact,
                                    const std::vector<std::string>& sensors) {
  GreyCandidateFit f{FieldGreyBoxSpec(z_ref_mm, blank_contact), FieldGreyBoxOptions(blank_contact)};
  f.spec.offset_sensors.clear();
  for (const std::string& s : sensors)
    if (s != kBlankContactSensor) f.spec.offset_sensors.push_back(s);
  f.spec.slope_sensors = f.spec.offset_sensors;
  return f;
}

drift::GreyBoxOptions ShortRecordStrongPrior(drift::GreyBoxOptions options) {
  options.short_record_strength_grid = {1.0};
  return options;
}

drift::GreyBoxOptions ShortRecordOffsetLags(drift::GreyBoxOptions options, int lags) {
  options.short_record_offset_lags = lags;
  return options;
}

bool EverySensorByDays(const drift::ShopRecord& record, const drift::GreyBoxOptions& options) {
  return drift::ScoresForward(record, options);
}

drift::GreyBoxSpec FieldGreyBoxSpec(double z_ref_mm, bool blank_contact) {
  constexpr double kAlphaScrew = 11.5e-6, kAlphaBed = 10.5e-6, kAlphaBlank = 11.8e-6;
  drift::GreyBoxSpec s;
  s.offset_sensors = {"head_bearing_C", "head_housing_C", "bed_middle_C"};
  s.slope_sensors = {"ambient_C", "z_nut_C"};
  s.blank_sensor = blank_contact ? kBlankContactSensor : "ambient_C";
  s.z_ref_mm = z_ref_mm;
  s.offset_prior = {{"bed_middle_C", -kAlphaBed * 1e3 * z_ref_mm},
                    {"head_housing_C", kAlphaScrew * 1e6 * 0.15},
                    {"head_bearing_C", kAlphaScrew * 1e6 * 0.03}};
  s.slope_prior = {{"ambient_C", 0.5 * kAlphaScrew * 1e6}, {"z_nut_C", 0.5 * kAlphaScrew * 1e6}};
  s.blank_prior = -kAlphaBlank * 1e6;
  return s;
}

drift::GreyBoxOptions FieldGreyBoxOptions(bool blank_contact, bool slope_lags_only) {
  drift::GreyBoxOptions o;
  o.validation = drift::GreyValidation::kForwardLeads;
  o.instant_slope_inputs = !slope_lags_only;
  if (blank_contact) o.blank_tau_grid = {kBlankContactTauMin};  // a held reading: no lag
  return o;
}

ShopControl ShopControlModels(const drift::JointDriftModel& model,
                              const std::vector<drift::Run>& training_logs) {
  ShopControl c;
  std::tie(c.offset, c.slope) = drift::ToDriftModels(model);
  const Eigen::Index p = model.features();
  if (p == 0) return c;
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(p, 1e300), hi = -lo;
  for (const drift::Run& log : training_logs) {
    if (log.samples() == 0) continue;
    const Eigen::MatrixXd x = drift::MonitorDesign(c.offset, log, drift::ReferenceMode::kRunStart);
    lo = lo.cwiseMin(x.rightCols(p).colwise().minCoeff().transpose());
    hi = hi.cwiseMax(x.rightCols(p).colwise().maxCoeff().transpose());
  }
  if (!(lo.array() <= hi.array()).all()) return c;
  for (drift::DriftModel* m : {&c.offset, &c.slope}) {
    m->feature_min = lo;
    m->feature_max = hi;
  }
  c.ranged = true;
  return c;
}

}  // namespace whirl::machine_eval
