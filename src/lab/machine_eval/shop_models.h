#pragma once
// The machine drift models a shop can train from what it measures (field_history.h: probe and
// laser readings, the measured leads of past screws, set-up checks; never a truth channel), and
// the sensor model in the form the 840D drift action applies.
//
// FitShopModels: every family with the same records and the same estimator (drift/joint.h):
//   warmup    lags of power_on (the time since power-on);
//   schedule  lags of the control's duty signals (ScheduleInputs: Brecher, Hirsch and Weck 2004,
//             the control's own drive data);
//   sensors   the candidate with the smallest grouped cross-validated RMSE (leave one calendar
//             day out) among
//     sensors             forward choice from all sensors, own lags;
//     sensors+<rule>      the better sensor-free rule's inputs and lags, sensors added while the
//                         CV falls by more than 1 %;
//     <rule>              the better sensor-free rule itself (warmup or schedule by CV),
//   so the sensor model is never worse than the sensor-free rules in cross-validation; a slope is
//   learned only over the range the Z-spanning readings cover (JointFitOptions).
// The day logs carry the sensors (<name>_C) and the control's duty signals a SINUMERIK 840D has
// without wiring (power_on: 0 at the first row, the power-on sample; ring_on, cutting,
// ring_load_pct, z_speed_mm_min; machine/instruments.h DayLog).
#include <string>
#include <vector>

#include "drift/grey_box.h"
#include "drift/grey_mix.h"
#include "drift/joint.h"
#include "drift/measurements.h"
#include "drift/model.h"
#include "drift/run_file.h"

namespace whirl::machine_eval {

/// The control signals of the schedule rule (drift/grey_mix.h, the product's: one list).
using drift::ScheduleInputs;

struct ShopModels {
  drift::JointDriftModel sensors, warmup, schedule;
  std::string sensors_choice;  ///< which candidate the sensor model is (see above)
  /// The grey box, the both_grey row: FieldGreyBoxSpec's five physical sensors while the record
  /// holds fewer than 20 lead days (EverySensorByDays), every sensor (FieldGreyCandidate's spec)
  /// from then on (the eleventh round, docs/machine-history.md; FitShopModels'
  /// grey_five_sensors keeps the five always); empty (no input, 0 everywhere) when the record's
  /// logs lack one of the five.
  drift::GreyBoxModel grey;
  /// The opt-in grey boxes, fitted only when asked for and where the grey box is, in
  /// GreyCandidate's order: grey_all_sensors (FieldGreyCandidate), grey_sensors_by_days (a copy
  /// of that model or of `grey`, by EverySensorByDays), grey_short_prior (`grey`'s spec and
  /// options with ShortRecordStrongPrior; a copy of `grey` on a long record),
  /// grey_short_offset_as_read and grey_short_offset_one_lag (`grey`'s spec and options with
  /// ShortRecordOffsetLags 0 and 1; copies of `grey` on a long record).
  std::vector<drift::GreyBoxModel> grey_candidates;
  bool rule_is_schedule = false;  ///< the sensor-free base (schedule, else warmup) by its CV
  /// The ninth round's guard (grey_guarded: GuardGreyBox), chosen only when the opt-in grey
  /// boxes are asked for and the grey box is; keep_grey: both_grey's model, else the base rule.
  struct Guard {
    bool chosen = false, keep_grey = true;
    double grey_rms_um = 0, rule_rms_um = 0;
  } guard;
  /// The fourteenth round's mixes (grey_short_mix, grey_short_mix_fixed: ShortMixWeights), set
  /// with the guard: the grey box's share w of the line w grey + (1 - w) base rule; 1 (both_grey's
  /// line itself) on a record of 2 x forward_days lead days and more.
  /// computed: the weights were fitted (the opt-in rows, or the default's mix); applied:
  /// both_grey's line is the grey_short_mix line (FitShopModels' grey_short_mix, the field
  /// default since the fourteenth round's adoption; 1 on a long record: the grey box's line).
  struct Mix {
    double fitted_weight = 1, fixed_weight = 1;
    bool computed = false, applied = false;
  } mix;
};

/// The grey box of the field machine (drift/grey_box.h), its sensors placed by the physics:
/// offset from head_bearing, head_housing and bed_middle; slope from ambient and z_nut (the
/// screw lies between the hall's air and its nut); the blank from ambient (stock stored in the
/// hall). Priors (alpha x lengths; nominal values a shop reads off its drawings): bed_middle
/// -alpha_b z_ref (the bed carries the fixed bearing away from the chuck), head_housing
/// alpha_s (L_housing + L_carriage) = 0.15 m, head_bearing alpha_s 0.03 m; the screw's slope
/// alpha_s 1e6 per 1000 mm split equally between ambient and z_nut; the blank -alpha_w 1e6.
/// alpha_s = 11.5e-6, alpha_b = 10.5e-6, alpha_w = 11.8e-6 1/K.
/// With `blank_contact` (the logs hold kBlankContactSensor, machine/field.h blank_contact_std_k)
/// the blank is that reading instead of ambient's lag: FitShopModels then fixes the blank's time
/// constant at kBlankContactTauMin (a reading held since clamping needs no lag; the evaluator's
/// lag only follows its steps).
inline constexpr const char* kBlankContactSensor = "blank_contact_C";
inline constexpr double kBlankContactTauMin = 0.5;
drift::GreyBoxSpec FieldGreyBoxSpec(double z_ref_mm, bool blank_contact = false);
/// The grey box's fit options in the field: drift::GreyBoxOptions' grids, its choices by forward
/// chaining on the leads (GreyValidation::kForwardLeads: the fourth round of issue 41,
/// docs/machine-history.md); with `blank_contact` the blank's time constant fixed at
/// kBlankContactTauMin; with `slope_lags_only` the slope sensors enter through their lags only
/// (GreyBoxOptions::instant_slope_inputs false; the offset's as read), an opt-in candidate.
drift::GreyBoxOptions FieldGreyBoxOptions(bool blank_contact = false, bool slope_lags_only = false);
/// The opt-in grey box of every sensor (grey_all_sensors, machine_eval.h GreyCandidate;
/// docs/machine-history.md "Eighth round: split"), from the field grey box's spec and options
/// (`sensors`: the record's temperature sensors): every sensor on both channels, the field spec's
/// priors, the others 0 (the grey box's structure trained on the exact truth leaves 1.4 um more
/// than the ceiling's 13 sensors, with every sensor 0.6 um less). (The eighth round's other row,
/// the leads carrying 0.9 of the weight, became drift::GreyBoxOptions' default.)
struct GreyCandidateFit {
  drift::GreyBoxSpec spec;
  drift::GreyBoxOptions options;
};
GreyCandidateFit FieldGreyCandidate(double z_ref_mm, bool blank_contact,
                                    const std::vector<std::string>& sensors);
/// The tenth round's row (grey_sensors_by_days; docs/machine-history.md "Tenth round:
/// split"), the field grey box's default since the eleventh round: every sensor
/// (FieldGreyCandidate) once the record holds enough lead days for the grey box's forward
/// chaining (drift::ScoresForward: 2 x forward_days), the field grey box's five sensors before
/// (every sensor pays on a short record and gains on a long one).
bool EverySensorByDays(const drift::ShopRecord& record, const drift::GreyBoxOptions& options);
/// The twelfth round's row (grey_short_prior; docs/machine-history.md "Twelfth round:
/// split"): `options` with the prior strength fixed at 1 while the record holds fewer than
/// 2 x forward_days lead days (drift::GreyBoxOptions::short_record_strength_grid = {1}: the
/// physical prior weighs as much as the data where 5 held-out days cannot choose a strength);
/// unchanged from 2 x forward_days lead days on.
drift::GreyBoxOptions ShortRecordStrongPrior(drift::GreyBoxOptions options);
/// The thirteenth round's rows (grey_short_offset_as_read, grey_short_offset_one_lag;
/// docs/machine-history.md "Thirteenth round: split"): `options` with the offset sensors
/// keeping only the first `lags` of the chosen lags (0: as read) while the record holds fewer
/// than 2 x forward_days lead days (drift::GreyBoxOptions::short_record_offset_lags: on 5 lead
/// days lags of the slow bed bend K0 along a cut); unchanged from 2 x forward_days lead days on.
drift::GreyBoxOptions ShortRecordOffsetLags(drift::GreyBoxOptions options, int lags);

/// The ninth round's guard (grey_guarded; docs/machine-history.md "Ninth round: split") and
/// its combination weight: the product's (drift/grey_mix.h), which whirl drift fit-grey runs too.
using drift::GuardGreyBox;
using drift::GuardScore;
/// The fourteenth round's rows (docs/machine-history.md "Fourteenth round: split"): the grey
/// box's share w of the machine line w grey + (1 - w) base rule while the record holds fewer than
/// 2 x forward_days lead days (drift::ScoresForward false), 1 from then on. grey_short_mix:
/// drift::ShortMixWeight, the guard's combination weight clamped to [kShortMixFloor, 1] (the
/// product's, the field default); grey_short_mix_fixed: kShortMixFixedWeight.
using drift::kShortMixFloor;
inline constexpr double kShortMixFixedWeight = 0.75;
ShopModels::Mix ShortMixWeights(bool long_record, const GuardScore& guard);
/// `z_fixed_mm`: the slope's reference (the Z screw's fixed bearing); `grey_slope_lags_only`:
/// FieldGreyBoxOptions' `slope_lags_only` for the grey box; `grey_candidates`: also fit
/// ShopModels::grey_candidates; `grey_five_sensors`: the grey box keeps FieldGreyBoxSpec's five
/// sensors on a long record too (the model before the eleventh round, an opt-in);
/// `grey_short_mix`: fit the mix's weights and let both_grey apply the grey_short_mix line
/// (ShopModels::Mix::applied; FieldProtocol's default, false here for the callers that fit the
/// grey box alone).
ShopModels FitShopModels(const drift::ShopRecord& record, double z_fixed_mm,
                         const std::vector<std::string>& schedule_inputs = ScheduleInputs(),
                         bool grey_slope_lags_only = false, bool grey_candidates = false,
                         bool grey_five_sensors = false, bool grey_short_mix = false);

/// A joint model's drift action models with their training ranges: the product's
/// (drift/grey_mix.h), which whirl drift fit-grey writes for the mix's rule.
using drift::ShopControl;
using drift::ShopControlModels;

}  // namespace whirl::machine_eval
