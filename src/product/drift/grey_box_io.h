#pragma once
// Files of the grey-box estimator (drift/grey_box.h): the model a shop fits (whirl drift
// fit-grey) and hands to the control (whirl drift nc --grey-model), and the spec it is fitted to.
//
// Model file (JSON, "format": "whirl-grey-box-model", "schema_version": 1):
//   offset_sensors, slope_sensors   column names of the day logs (<name>_C), in order
//   blank_sensor                    the blank's estimate's input, "" for none
//   offset_duty, slope_duty         optional: duty inputs (other columns of the logs, as logged,
//                                   e.g. ring_load_pct), after the sensors of their channel
//   time_constants_min              the shared lags, ascending, each in (0, 1e6] min
//   z_ref_mm                        the slope's reference (the Z screw's fixed bearing), mm
//                                   in the readings' z, within +-1e5 (kAxisPositionRange; a
//                                   bearing behind the chuck face is negative)
//   offset_features, slope_features one object per feature, input-major (T - 20, then its lags):
//                                   name, input, tau_min (0: the input itself), coefficient
//                                   (um per K; slope: um per 1000 mm per K, |c| <= 1e4), and its
//                                   training range train_min_k, train_max_k [K against 20 degC,
//                                   within kGreyFeatureRangeK; a duty input's own unit]; then each
//                                   duty input and its lags
//   slope_intercept_um_per_1000     g0, |g0| <= 1e5 (0.1 mm/mm, the largest MD32760)
//   blank                           null without a blank sensor, else {tau_min (0, 1e6],
//                                   um_per_1000_per_k (|g_b| <= 1e4), train_min_c, train_max_c
//                                   within kGreyBlankRangeC}
//   fit                             {prior_strength >= 0, cv_rmse_um in [0, 1e6], rows >= 0}
//   training                        {notes: provenance}
//   mix                             only in schema_version 2 (and required there): the short
//                                   record's mix (drift/grey_mix.h) the control runs,
//                                   w grey + (1 - w) rule: {weight (the grey box's w, within
//                                   [kShortMixFloor, 1)), rule ("warmup" | "schedule"),
//                                   rule_offset, rule_slope (the rule's drift models,
//                                   whirl-drift-model objects: K0 um, slope um per 1000 mm),
//                                   guard {days, grey_rms_um, rule_rms_um, combination_weight}}
// A file without the mix is schema_version 1 (the file as before the mix); a reader that knows
// only version 1 refuses a version 2 file rather than run the grey box alone.
// Every number is range-checked on reading; an error names the file, the field and the rule.
//
// Spec file (JSON, "format": "whirl-grey-box-spec", "schema_version": 1): the sensors a shop
// placed and the physical priors it reads off its drawings:
//   offset_sensors, slope_sensors, blank_sensor ("" for none), optional offset_duty and
//   slope_duty (duty inputs, prior 0), z_ref_mm (kAxisPositionRange),
//   offset_prior_um_per_k {sensor: um per K}, slope_prior_um_per_1000_per_k {sensor: value},
//   blank_prior_um_per_1000_per_k (-alpha_w x 1e6; steel -11.8).
// A prior key that names no sensor of its list is an error (it would be ignored silently).
// Shipped example for the simulated field machine: datasets/machines/field_grey_box_spec.json.
#include <filesystem>
#include <optional>
#include <string>
#include <nlohmann/json.hpp>

#include "core/limits.h"
#include "drift/grey_box.h"
#include "drift/grey_mix.h"
#include "drift/model.h"

namespace whirl::drift {

inline constexpr const char* kGreyBoxFormat = "whirl-grey-box-model";
inline constexpr int kGreyBoxSchemaVersion = 1;
inline constexpr int kGreyBoxMixSchemaVersion = 2;  ///< a file with the mix part
inline constexpr const char* kGreyBoxSpecFormat = "whirl-grey-box-spec";
/// Largest |coefficient| of a feature (um per K, or um per 1000 mm per K): 100 x the growth of a
/// 10 m steel bed per K (110 um/K); larger is a corrupt file.
inline constexpr double kMaxGreyCoefficient = 1e4;
/// Largest |slope intercept| [um per 1000 mm]: 0.1 mm/mm, the largest MD32760 (SD43910's cap).
inline constexpr double kMaxGreyIntercept = 1e5;
/// A temperature feature's training range [K against 20 degC]: T - 20 and its lags (averages of
/// T - 20) for a T that a run file accepts (drift/run_file.h, kMinTemperatureC..kMaxTemperatureC).
inline constexpr Range kGreyFeatureRangeK{kMinTemperatureC - 20, kMaxTemperatureC - 20, false, "K",
                                          "T - 20 degC for T a run file accepts"};
/// The blank's training range [degC]: a lag of a sensor's T, so within what a run file accepts.
inline constexpr Range kGreyBlankRangeC{kMinTemperatureC, kMaxTemperatureC, false, "degC",
                                        "a temperature a run file accepts"};
/// Largest |value| of a duty input's training range, in its own unit (a feed in mm/min or a
/// speed in 1/min stays far below; beyond it is a corrupt file).
inline constexpr double kMaxGreyDutyValue = 1e6;

/// InputError naming the field and the rule: sizes, ascending lags, every range above.
void ValidateGreyBox(const GreyBoxModel& m);

void to_json(nlohmann::json& j, const GreyBoxModel& m);
void from_json(const nlohmann::json& j, GreyBoxModel& m);
/// InputError naming the file, the field and the rule. The grey box part only (a mix part is
/// read and checked, then left out: ReadGreyBoxFile keeps it).
GreyBoxModel ReadGreyBoxModel(const std::filesystem::path& path);
/// Validates, then writes atomically (schema_version 1, no mix).
void WriteGreyBoxModel(const std::filesystem::path& path, const GreyBoxModel& m);

/// The model file's optional mix part (see above; drift/grey_mix.h FitGreyMix).
struct GreyBoxMix {
  double weight = 1;  ///< the grey box's share w
  std::string rule;   ///< "warmup" or "schedule"
  DriftModel rule_offset, rule_slope;
  GuardScore guard;
};
struct GreyBoxFile {
  GreyBoxModel model;
  std::optional<GreyBoxMix> mix;
};
/// The mix part for the grey box fitted on `record`: FitGreyMix's rule as drift models with its
/// training ranges (ShopControlModels over the record's day logs); nullopt on a long record or
/// where w = 1 (the grey box's line itself).
std::optional<GreyBoxMix> GreyBoxMixPart(const GreyMix& mix, const ShopRecord& record);
/// InputError naming the file, the field and the rule: the grey box as ReadGreyBoxModel, the
/// mix's weight within [kShortMixFloor, 1), a rule other than warmup or schedule, rule models
/// that read sensors (the mix runs one reference: the grey box's absolute temperatures).
GreyBoxFile ReadGreyBoxFile(const std::filesystem::path& path);
/// Validates, then writes atomically: schema_version 2 with the mix, else 1.
void WriteGreyBoxFile(const std::filesystem::path& path, const GreyBoxFile& f);

/// InputError naming the file, the field and the rule (a sensor named twice, a prior for a
/// sensor not in its list, no offset or slope sensor).
GreyBoxSpec ReadGreyBoxSpec(const std::filesystem::path& path);

/// The grey box as the drift action's two linear models (interp/drift_action.h), evaluated with
/// reference "model" at 20 degC, so each input is T - 20 with lags L_0 = u_0 (GreyBoxEvaluator):
///   offset: sensors = offset_sensors, b0 = 0, b = a          [um]
///   slope:  sensors = slope_sensors,  b0 = g0, b = g         [um per 1000 mm]
/// with the grey box's training ranges. The blank term g_b (B_latched - 20) is not in them: the
/// drift action adds it from the latched slot (interp::BlankTerm).
struct GreyBoxControl {
  DriftModel offset, slope;
};
GreyBoxControl GreyBoxControlModels(const GreyBoxModel& m);

}  // namespace whirl::drift
