#include "machine_eval/shop_models.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <tuple>
#include <utility>

#include "core/error.h"
#include "machine_eval/machine_eval.h"

namespace whirl::machine_eval {

ShopModels::Mix ShortMixWeights(bool long_record, const GuardScore& guard) {
  if (long_record) return {};
  return {drift::ShortMixWeight(false, guard), kShortMixFixedWeight};
}

ShopModels FitShopModels(const drift::ShopRecord& record, double z_fixed_mm,
                         const std::vector<std::string>& schedule_inputs, bool grey_slope_lags_only,
                         bool grey_candidates, bool grey_five_sensors, bool grey_short_mix) {
  ShopModels m;
  const drift::BaseRules rules = drift::FitBaseRules(record, z_fixed_mm, schedule_inputs);
  m.warmup = rules.warmup;
  m.schedule = rules.schedule;
  const bool schedule_base = rules.is_schedule;
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
  const GuardScore g = drift::GuardGreyBox(
      record, applied, grey_options,
      drift::SensorFreeRuleSpec(z_fixed_mm, schedule_base
                                                ? schedule_inputs
                                                : std::vector<std::string>{drift::kWarmupInput}),
      drift::SensorFreeRuleOptions());
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

}  // namespace whirl::machine_eval
