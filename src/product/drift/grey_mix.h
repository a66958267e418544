#pragma once
// The grey box's mix with a sensor-free rule on a short record (docs/machine-history.md
// "Fourteenth round"; the field default since its adoption): while the shop's record holds fewer
// than 2 x forward_days lead days (ScoresForward false: 20 with GreyBoxOptions' defaults) the
// machine line is w grey + (1 - w) base rule, the base rule the better sensor-free rule by its
// grouped CV (warmup: lags of power_on; schedule: lags of the control's duty signals), w the
// guard's combination weight on the record's last two lead days, clamped to [kShortMixFloor, 1].
// The lab (machine_eval/shop_models.h) and the shop (whirl drift fit-grey) both call these.
#include <string>
#include <vector>

#include "drift/grey_box.h"
#include "drift/joint.h"
#include "drift/measurements.h"
#include "drift/model.h"
#include "drift/run_file.h"

namespace whirl::drift {

/// The control signals of the schedule rule: ring_on, cutting, ring_load_pct, z_speed_mm_min
/// (Brecher, Hirsch and Weck 2004: the control's own drive data).
std::vector<std::string> ScheduleInputs();
/// The warmup rule's one input: the time since power-on (0 at the day log's first row).
inline constexpr const char* kWarmupInput = "power_on";

/// A sensor-free rule's spec (control signals as logged, about `z_ref_mm`) and options (at least
/// one lag: a step such as power_on carries no information without one).
JointSpec SensorFreeRuleSpec(double z_ref_mm, std::vector<std::string> inputs);
JointFitOptions SensorFreeRuleOptions();

/// Both sensor-free rules fitted on the record; the base rule is schedule when its grouped CV
/// RMSE is at most warmup's, else warmup.
struct BaseRules {
  JointDriftModel warmup, schedule;
  bool is_schedule = false;
  const JointDriftModel& Base() const { return is_schedule ? schedule : warmup; }
  std::string BaseName() const { return is_schedule ? "schedule" : "warmup"; }
};
BaseRules FitBaseRules(const ShopRecord& record, double z_ref_mm,
                       const std::vector<std::string>& schedule_inputs = ScheduleInputs());

/// The ninth round's guard (docs/machine-history.md "Ninth round: split"): the grey box or a
/// sensor-free rule, chosen on the shop's own record in time order. For each of the last
/// `held_days` calendar days that hold a lead record, both are fitted on the records of the days
/// before it only and that day's leads predicted; the score is the weighted (1 / sigma^2) RMS of
/// the lead residuals, each lead record's about its own weighted mean (a lead is known up to a
/// constant), pooled over the days. keep_grey: the grey box's score is at most the rule's, or no
/// day could be scored (a fit failed or no earlier day): the grey box stays. Only the record's
/// past enters; the caller applies the family fitted on all of it.
/// combination_weight: the least-squares weight w of the grey box in w grey + (1 - w) rule on
/// the same pooled demeaned residuals, sum s e_r (e_r - e_g) / sum s (e_r - e_g)^2 (Bates and
/// Granger 1969, "The combination of forecasts"), unclamped; 1 when no day was scored or the two
/// families' residuals are equal.
struct GuardScore {
  bool keep_grey = true;
  double grey_rms_um = 0, rule_rms_um = 0;  ///< 0 when no day was scored
  int days = 0;                             ///< days scored
  double combination_weight = 1;
};
GuardScore GuardGreyBox(const ShopRecord& record, const GreyBoxSpec& grey,
                        const GreyBoxOptions& grey_options, const JointSpec& rule,
                        const JointFitOptions& rule_options, int held_days = 2);

/// The grey box's share w of the short record's mix: the guard's combination weight clamped to
/// [kShortMixFloor, 1] (the grey box is never dropped, so a wrong judge costs at most half the
/// gap); 1 (the grey box's line itself) on a long record (ScoresForward).
inline constexpr double kShortMixFloor = 0.5;
double ShortMixWeight(bool long_record, const GuardScore& guard);

/// InputError naming the day log (`log_sources[i]`, else the log's own source) and the column
/// when a day log lacks a control signal a sensor-free rule reads (power_on, schedule_inputs).
void RequireRuleColumns(const ShopRecord& record, const std::vector<std::string>& log_sources,
                        const std::vector<std::string>& schedule_inputs = ScheduleInputs());

/// The shop's mix for a grey box of `spec` and `options` fitted on `record`: the base rule, the
/// guard's score (the grey box of `spec` and `options` against the base rule) and w
/// (ShortMixWeight). `applies` false on a long record (LongRecord: at least 2 x forward_days
/// lead days; w = 1, no rule fitted, no guard run). With kForwardLeads (the field's and
/// fit-grey's default) this is machine_eval::FitShopModels' grey_short_mix for the same grey box.
struct GreyMix {
  bool applies = false;
  BaseRules rules;
  GuardScore guard;
  double weight = 1;
};
GreyMix FitGreyMix(const ShopRecord& record, const GreyBoxSpec& spec, const GreyBoxOptions& options,
                   const std::vector<std::string>& schedule_inputs = ScheduleInputs());

/// A joint model's offset (K0) and slope (per 1000 mm) channels as the drift action's models
/// (ToDriftModels), with the features' range over the day logs it was trained on
/// (MonitorDesign with rises from each log's first row): the range the drift action's slope
/// bound and the monitor's scaling read. `ranged` false: no feature or no log sample, the ranges
/// stay as ToDriftModels leaves them (unbounded).
struct ShopControl {
  DriftModel offset, slope;
  bool ranged = false;
};
ShopControl ShopControlModels(const JointDriftModel& model, const std::vector<Run>& training_logs);

}  // namespace whirl::drift
