#pragma once
// Both halves of the compensation on a drifting machine, the manual of the machine_eval module
// (lab): the strategy comparison of compare/compare.h (the workpiece's own thermal elongation)
// on the one simulated machine world, the field world of machine/ (a machine as a thermal network
// living a shop's calendar: warm-up tests, a laser test, past production days, nights and
// weekends; machine/scenarios.h names its scenarios). Every figure it gives is measured in the
// project's simulator, not on a machine. Driven by `whirl machine evaluate` and step 7 of `whirl
// demo`.
//
// Sources.
//   Workpiece half: Li Yanfeng, Ma Hongjun and Jiang Hongkui (Shandong Jianzhu University),
//     "Research on the thermal elongation of screws in hard whirling based on a BP neural network"
//     (in Chinese; network prediction of the elongation's maximum and settle time, arctangent
//     curve, piecewise-linear compensation on a SINUMERIK 840D).
//   Machine half: Miao Enming, Gao Zenghan, Dang Lianchun and Miao Jichao (Hefei University of
//     Technology), "Analysis of the thermal error characteristics of CNC machine tools" (in
//     Chinese; temperature-sensitive points, regression of the thermal error on temperature
//     rises); Brecher, Hirsch and Weck, "Compensation of thermo-elastic machine tool deformation
//     based on control internal data", CIRP Annals 53(1), 2004 (the schedule rule).
//   Set-up checks: the patent "Temperature compensation method, system and medium for CNC machine
//     tools" (Xi'an University of Posts and Telecommunications): an on-line check of the model
//     and an update when it disagrees (drift/monitor.h; field_monitor.h).
//   Control: Siemens, SINUMERIK 840D Function Manual Extended Functions, K3 (temperature
//     compensation, SD43900-43920; interp/sinumerik.h, interp/drift_action.h).
//
// The pieces, in the order the data travels:
//   field_history.h  what a shop measures before the test window (probe, laser, the leads of past
//                    screws, set-up checks): the only input of training;
//   shop_models.h    what a shop trains from it (warmup, schedule, the sensor model; one
//                    estimator, drift/joint.h) and the sensor model as the 840D drift action's
//                    models (ShopControlModels);
//   strategies.h     how the control applies a model: causally, zero-order hold of the latest
//                    control sample;
//   field_monitor.h  the sensor model kept valid by the probe checks at the test day's set-ups;
//   field_eval.h     the evaluation of a scenario, over seeds, and of several scenarios;
//   summary.h        pooled statistics over seeds, the headlines, the tables and the JSON.
// The evaluation returns results (the types below) and writes nothing: the report of one screw
// and its combined 840D programs are the lab's report module, machine_report/, built from the
// ReportScrew an evaluation keeps on request.
//
// Strategies, one list (the rows of the table, in this order; compensation c(t), um):
//   none               0
//   traditional        the strongest history rule's 840D plan (class, table or nearest, chosen
//                      by leave-one-out on the history table, compare/history_rules.h)
//   workpiece          the network's 840D plan (compare.h "model")
//   class, table, nearest  each history rule's plan
//   warmup             workpiece + the time-since-power-on rule (lags of power_on)
//   schedule           workpiece + the control-signal rule (lags of ring_on, cutting,
//                      ring_load_pct, z_speed_mm_min)
//   lead_slope         workpiece + a pitch correction learned from measured past screws
//                      (field_history.h LeadSlopeFor)
//   machine_shop       the sensor model alone (trained from the shop's measurements only)
//   both_shop          workpiece + machine_shop: the both halves a shop can train; its sensor model
//                      is what the report's programs apply
//   both_shop_monitor  both_shop with the offset channel updated on the test day from the probe
//                      checks at its set-ups (field_monitor.h)
//   both_grey          workpiece + the grey box (drift/grey_box.h: absolute temperatures, a slope
//                      intercept, the blank's estimate latched at the cut start, physical priors;
//                      shop_models.h FieldGreyBoxSpec), trained from the same shop records;
//                      below 2 x forward_days lead days mixed with the sensor-free base rule,
//                      w grey + (1 - w) rule (grey_short_mix's line, FieldProtocol::
//                      grey_short_mix, the default since the fourteenth round); the report's
//                      840D programs apply it wherever it was fitted
//                      (ReportScrew::programs_strategy)
// Every machine model is applied causally (strategies.h). The truth of a cut: the workpiece truth
// of compare::CompareScrew (the blank starts at the hall's temperature through its lag and
// follows the hall over the cut) plus the machine's truth m(t, z) along the cut
// (machine/truth.h: head, Z axis, and the blank cut warm and measured at 20 degC).
// What is left (both_shop): the residual lead error of the workpiece part (e - c_wp) and of the
// machine part (m - c_m) are measured separately; the larger accumulated error over the thread
// dominates. The uncompensated pattern is split the same way into workpiece, head and Z axis.
//
// The legacy world (a closed-form machine, one cut per day from cold, with rows trained on the
// simulator's exact error channels) was retired: docs/machine-evaluation.md says why; its
// protocol lives on as the field scenario constant-duty.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "drift/grey_box.h"
#include "drift/joint.h"
#include "drift/model.h"
#include "drift/run_file.h"
#include "fit/arctan_curve.h"
#include "interp/sinumerik.h"
#include "lead/iso3408.h"
#include "lead/lead.h"
#include "lead/metrics.h"
#include "screw/screw.h"

namespace whirl::machine_eval {

enum class MachineStrategy {
  kNone,
  kTraditional,
  kWorkpiece,
  kClass,
  kTable,
  kNearest,
  kWarmup,
  kSchedule,
  kLeadSlope,
  kMachineShop,
  kBothShop,
  kBothShopMonitor,
  kBothGrey
};
inline constexpr std::size_t kMachineStrategyCount = 13;
/// The strategies in table order (the header comment's list).
std::array<MachineStrategy, kMachineStrategyCount> MachineStrategies();
/// none, traditional, workpiece, class, table, nearest, warmup, schedule, lead_slope,
/// machine_shop, both_shop, both_shop_monitor, both_grey
std::string ToString(MachineStrategy s);
/// Whether a strategy's machine half uses temperature sensors (machine_shop, both_shop,
/// both_shop_monitor, both_grey); the others are sensor-free.
bool UsesSensors(MachineStrategy s);

/// Opt-in rows (issue 41, seventh round; FieldProtocol::offset_candidates), after the table's
/// rows: the workpiece plan + both_grey's slope (with its latched blank term) and another offset
/// K0(t): `warmup`'s (grey_warmup_k0) or the mean of warmup's and the grey box's
/// (grey_mean_k0). Both use sensors (the slope); never the strongest sensor-free row.
enum class OffsetCandidate { kGreyWarmupOffset, kGreyMeanOffset };
inline constexpr std::size_t kOffsetCandidateCount = 2;
std::string ToString(OffsetCandidate c);  ///< grey_warmup_k0, grey_mean_k0
/// warmup's share of the candidate's K0 (1 and 0.5; the grey box's share is 1 minus it).
double WarmupOffsetShare(OffsetCandidate c);

/// Opt-in rows of the eighth to tenth rounds (issue 41; FieldProtocol::grey_candidates), after
/// the OffsetCandidate rows (which come with them), from the same shop records as both_grey:
/// the workpiece plan + the grey box of every sensor (grey_all_sensors, shop_models.h
/// FieldGreyCandidate); + that grey box once the record holds 2 x forward_days lead days,
/// both_grey's before (grey_sensors_by_days, shop_models.h EverySensorByDays); or + both_grey's
/// grey box or the sensor-free base rule (warmup or schedule), whichever the shop's own last
/// lead days favour (grey_guarded, GuardGreyBox); the twelfth round's both_grey with the prior
/// strength fixed at 1 below 2 x forward_days lead days (grey_short_prior, shop_models.h
/// ShortRecordStrongPrior); the thirteenth round's both_grey with the offset sensors as read
/// (grey_short_offset_as_read) or through the shortest chosen lag (grey_short_offset_one_lag)
/// below 2 x forward_days lead days (shop_models.h ShortRecordOffsetLags), before grey_guarded;
/// after it the fourteenth round's line w grey box + (1 - w) base rule below 2 x forward_days
/// lead days, w from the guard's held days (grey_short_mix) or fixed (grey_short_mix_fixed;
/// shop_models.h ShortMixWeights). All count as using sensors; never the strongest sensor-free
/// row.
enum class GreyCandidate {
  kAllSensors,
  kSensorsByDays,
  kShortPrior,
  kShortOffsetAsRead,
  kShortOffsetOneLag,
  kGuarded,
  kShortMix,
  kShortMixFixed
};
inline constexpr std::size_t kGreyCandidateCount = 8;
/// grey_all_sensors, grey_sensors_by_days, grey_short_prior, grey_short_offset_as_read,
/// grey_short_offset_one_lag, grey_guarded, grey_short_mix, grey_short_mix_fixed
std::string ToString(GreyCandidate c);
/// The name of opt-in row k (OffsetCandidate rows, then GreyCandidate rows).
std::string OptInRowName(std::size_t k);

/// Sources of the uncompensated lead error (accumulated over the thread, um, each alone).
enum class ErrorSource { kWorkpiece, kHead, kZAxis };
inline constexpr std::size_t kErrorSourceCount = 3;
std::string ToString(ErrorSource s);  ///< workpiece, head, z_axis (the Z axis and the blank)

/// One test-day screw, every strategy.
struct MachineEvalScrew {
  int machine = 0;
  int day = 0;             ///< calendar day of the cut (0 = the first test day)
  std::string start_type;  ///< cold, warm, interrupted, long_pause (machine/day.h)
  screw::Screw screw;
  std::uint64_t seed = 0, day_seed = 0;
  bool ok = false;
  std::string error;
  std::array<lead::LeadMetrics, kMachineStrategyCount> metrics;
  std::array<lead::IsoClass, kMachineStrategyCount> iso{};
  /// Uncompensated accumulated error over the thread of each source alone, um.
  std::array<double, kErrorSourceCount> source_total_um{};
  /// both_shop: accumulated error over the thread of the workpiece and machine residuals, um.
  double residual_workpiece_total_um = 0, residual_machine_total_um = 0;
  /// The opt-in rows (OptInRowName order); empty unless asked for.
  std::vector<lead::LeadMetrics> candidate_metrics;
  std::vector<lead::IsoClass> candidate_iso;
};

struct MachineEvalSummary {
  std::size_t screws = 0, failed = 0;
  std::array<double, kErrorSourceCount> source_median_um{};  ///< uncompensated, per source
  std::size_t residual_workpiece_dominates = 0, residual_machine_dominates = 0;
  std::string message;
};

/// One screw kept for the report (machine_report/): its figures, its curves, and the models its
/// combined 840D programs apply (the sensor model of both_shop, trained from the shop's
/// measurements only).
struct ReportScrew {
  std::string scenario;
  MachineEvalScrew result;
  std::array<lead::LeadDeviation, kMachineStrategyCount> leads;  ///< per strategy
  /// Per strategy: the sd of its compensation from its training data only, um (0 for none; the
  /// report's +-1 sd bands): the network's predictive sd of the maximum elongation; a history
  /// rule's leave-one-out mean relative error on the history times its plateau; warmup,
  /// schedule, the sensor model (and the monitored one) and the grey box: their grouped CV RMSE
  /// over the shop's records; lead_slope: the sd of the past screws' slopes over the thread;
  /// a strategy of two halves: both in quadrature.
  std::array<double, kMachineStrategyCount> sd_um{};
  /// The control's log of the screw's day (temperatures through the control's input filter, the
  /// duty signals) from power-on to two samples after the cut; time_min from the day's 00:00.
  drift::Run log;
  double cut_start_min = 0, cut_end_min = 0;  ///< in the log's time
  fit::ArctanCurve predicted_curve;           ///< the network's curve (the workpiece plan's)
  screw::Kinematics kinematics;
  interp::PlanOptions plan_options;  ///< the workpiece plan's tolerance and check step
  /// The sensor model both_shop applies (drift/joint.h), and its offset (K0) and slope (per
  /// 1000 mm) channels as the drift action's models, with the features' ranges over the training
  /// day logs (shop_models.h ShopControlModels).
  drift::JointDriftModel sensor_model;
  drift::DriftModel offset, slope;
  std::vector<std::string> sensors;  ///< the sensor model's sensors
  std::string sensors_choice;        ///< which candidate it is (shop_models.h)
  double z_ref_mm = 0;               ///< the slope's reference: the Z screw's fixed bearing
  drift::GreyBoxModel grey;          ///< the grey box both_grey applies (no input: not fitted)
  /// grey_short_mix where its row was computed (the opt-in grey rows, the guard chosen): the
  /// grey box's weight w (shop_models.h ShortMixWeights; 1: the grey box's line), the base rule
  /// it is mixed with (warmup or schedule, `mix_rule_name`) and that rule as the drift action's
  /// offset and slope models (ShopControlModels); mix_computed false otherwise.
  bool mix_computed = false;
  bool mix_applied = false;  ///< both_grey applies the mix (FieldProtocol::grey_short_mix)
  double mix_weight = 1;
  std::string mix_rule_name;
  drift::JointDriftModel mix_rule;
  drift::DriftModel mix_rule_offset, mix_rule_slope;
  /// The machine model the report's combined 840D programs apply: kBothGrey where the grey box
  /// was fitted (ProgramsStrategy, summary.h: a rule fixed before the test days), else
  /// kBothShop; and why.
  MachineStrategy programs_strategy = MachineStrategy::kBothShop;
  std::string programs_reason = "both_shop: no evaluation over seeds chose between the models";
};

struct MachineEvaluation {
  /// Per machine: the sensor model's sensors and which candidate it is (shop_models.h).
  std::vector<std::vector<std::string>> sensors;
  std::vector<std::string> sensors_choice;
  /// Per machine, when the opt-in grey rows were asked for: what grey_guarded applies
  /// ("both_grey", "warmup" or "schedule"; shop_models.h GuardGreyBox); else empty.
  std::vector<std::string> guard_choice;
  /// Per machine, when the opt-in grey rows were asked for: grey_short_mix's weight w of the
  /// grey box (shop_models.h ShortMixWeights); else empty.
  std::vector<double> short_mix_weight;
  /// Per machine, what the grey box's fit chose (drift::GreyBoxModel): the prior strength, the
  /// lags' time constants [min], the blank's [min], the validation RMSE [um], and the record's
  /// lead days (drift::LeadDays); strength 0 and no lag where no grey box was fitted.
  struct GreyFit {
    double prior_strength = 0, blank_tau_min = 0, cv_rmse_um = 0;
    std::vector<double> time_constants_min;
    int lead_days = 0;
  };
  std::vector<GreyFit> grey_fit;
  std::vector<MachineEvalScrew> screws;
  MachineEvalSummary summary;
  std::optional<ReportScrew> report;  ///< when asked for (FieldEvalOptions::keep_report_screw)
};

/// Counts, the uncompensated sources' medians, which residual dominates after both_shop, and a
/// one-line message with the rows' medians within 1000 mm.
MachineEvalSummary SummarizeMachineEval(const std::vector<MachineEvalScrew>& screws);

/// Schema "whirl.machine_evaluate_run" version 1: the summary, the sensor models' sensors and
/// choices per machine, and every screw with every strategy's metrics and ISO class.
void to_json(nlohmann::json& j, const MachineEvaluation& e);

}  // namespace whirl::machine_eval
