#pragma once
// Both halves of the compensation in one cut, the manual of the machine_eval module: the strategy
// comparison of compare/compare.h (the workpiece's own thermal elongation) on a whirling machine
// that drifts (machine/machine.h), compensated by the workpiece plan, by a machine drift model or
// by both; the combined 840D programs of one screw (machine_nc.h) and its report
// (machine_report.h). Driven by `whirl machine evaluate` and step 7 of `whirl demo` (demo.h).
// Every figure it gives is measured in the project's simulator, not on a machine. This header is
// the legacy world (machine/machine.h); the field world's scenarios are in field_eval.h.
//
// Sources.
//   Workpiece half: Li Yanfeng, Ma Hongjun and Jiang Hongkui (Shandong Jianzhu University),
//     "Research on the thermal elongation of screws in hard whirling based on a BP neural network"
//     (in Chinese; network prediction of the elongation's maximum and settle time, arctangent
//     curve, piecewise-linear compensation on a SINUMERIK 840D).
//   Machine half: Miao Enming, Gao Zenghan, Dang Lianchun and Miao Jichao (Hefei University of
//     Technology), "Analysis of the thermal error characteristics of CNC machine tools" (in
//     Chinese; temperature-sensitive points by fuzzy clustering and grey relational grade, multiple
//     linear regression of the thermal error on the temperature rises, and the finding that a model
//     trained in idle running does not carry over to cutting: the both_idle strategy).
//   Check bar: the patent "Temperature compensation method, system and medium for CNC machine
//     tools" (Xi'an University of Posts and Telecommunications): an on-line check of the model
//     with a check bar and a refit when it disagrees (drift/monitor.h; the both_monitor strategy).
//   Control: Siemens, SINUMERIK 840D Function Manual Extended Functions, K3 (temperature
//     compensation, SD43900-43920; interp/sinumerik.h, interp/drift_action.h).
//
// Inputs and units: the workpiece model (workpiece/model.h), the traditional rule's history and the ISO
// 3408-3 table (compare/), a base screw (its blank and machine settings; the screws are drawn
// around it, compare/evaluate.h RandomFeasibleScrews), the machine (machine/machine.h: a JSON file
// or machine::DefaultMachine()), and MachineEvalOptions below. Times in s or min as named, lengths
// in mm, errors and lead deviations in um, temperatures in degC.
//
// Truth of one screw on machine i, day d: e_tot(t) = e(t) + m(t, z(t)), e the workpiece truth of
// CompareScrew (same seed, disturbances on; with the machine's ambient component on, the blank
// follows the day's hall rate r, the same ramp the bed follows: one hall, not two independent
// draws), m the machine drift at the tool position z(t) = thread_start_position - v_f t
// [mm from the chuck face]. Lead deviation: compare/cut.h with e_tot.
// Strategies (compensation c(t), um):
//   none            0
//   traditional     the class-mean curve's 840D plan (as in compare.h)
//   workpiece       the network's 840D plan (compare.h "model")
//   machine         the machine model (trained on cutting runs) only:
//                   c_m(t) = K0(t) + G(t) (z_fixed - z(t)) / 1000, K0 and G the drift models of
//                   offset_um and zscrew_per_1000_um evaluated on the screw's own sensor log,
//                   linearly interpolated between its samples (the control evaluates the model
//                   every interpolation cycle from inputs read continuously)
//   both            workpiece + machine (cutting-trained)
//   both_idle       workpiece + machine trained on idle warm-ups (Miao et al.'s comparison)
//   both_monitor    both, with the offset model kept valid by the patent's check bar
//                   (drift/monitor.h MonitorRun on the screw's log: a check every
//                   `monitor_every_min`, measured at the fixed end (offset_um) with N(0, 0.5 um)
//                   noise from core/random.h, 3-sigma threshold, rule `offset` from the invalid
//                   check alone; the stops are not simulated: the log goes on as if the cut never
//                   paused)
//   The rows above are the legacy evaluation, unchanged. The rows below are the baselines a
//   shop uses and the models a shop can train (machine_eval/history.h: the training runs
//   measured by a probe and a laser, never read as exact channels), every machine model applied
//   causally (machine_eval/strategies.h: zero-order hold of the latest control sample):
//   class           the diameter-class means' 840D plan (today's "traditional" before the
//                   strongest history rule replaced it)
//   table, nearest  the experience table and the 3 nearest past screws (compare/history_rules.h)
//   warmup          workpiece + the time-since-power-on rule (lags of power_on)
//   schedule        workpiece + the control-signal rule (lags of ring_on, cutting, ring load;
//                   Brecher, Hirsch and Weck, "Compensation of thermo-elastic machine tool
//                   deformation based on control internal data", CIRP Annals 53(1), 2004)
//   machine_shop    the sensor model trained from the measurements only
//   both_shop       workpiece + machine_shop
//   lead_slope      workpiece + a pitch correction learned from measured past screws (field
//                   world, field_eval.h); the legacy protocol measures no past screw, so here it
//                   equals workpiece and is not a row of the legacy table
//   both_shop_monitor  both_shop with the offset channel kept valid on the test day by the probe
//                   checks a shop takes at set-ups (field world only, field_monitor.h); not a
//                   row of the legacy table (it has no set-ups)
// Machine models: per machine, `train_runs` idle warm-ups (ring turning, no cut, 180 min) and
// `train_runs` cutting runs (150 min, cutting speed uniform in 150..210 m/min) on their own days;
// drift::FitDriftModel (drift/fit.h; kind and sensor selection from `fit`, by default Miao et
// al.'s regression on their selected points) for each channel. With every machine component off,
// m = 0 and no machine model is fitted (c_m = 0): every strategy then equals its workpiece-only
// counterpart exactly.
// What is left (both): the residual lead error of the workpiece part (e - c_wp) and of the machine
// part (m - c_m) are measured separately; the larger accumulated error over the thread dominates.
// The uncompensated pattern is split the same way into workpiece, head, Z screw and bed.
// Seeds: machine i from MixSeed(seed, 0x4d00 + i), screw k's day from the machine's seed, its
// truth from MixSeed(seed, k) (core/random.h): results do not depend on the thread count.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "compare/evaluate.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "interp/machine_profile.h"
#include "machine/machine.h"
#include "machine_eval/history.h"

namespace whirl::machine_eval {

enum class MachineStrategy {
  kNone,
  kTraditional,
  kWorkpiece,
  kMachine,
  kBoth,
  kBothIdle,
  kBothMonitor,
  kClass,
  kTable,
  kNearest,
  kWarmup,
  kSchedule,
  kMachineShop,
  kBothShop,
  kLeadSlope,
  kBothShopMonitor
};
inline constexpr std::size_t kMachineStrategyCount = 16;
/// none, traditional, workpiece, machine, both, both_idle, both_monitor, class, table, nearest,
/// warmup, schedule, machine_shop, both_shop, lead_slope, both_shop_monitor
/// Whether a strategy's machine half uses temperature sensors (machine, both*, machine_shop,
/// both_shop, both_shop_monitor); the others are sensor-free.
bool UsesSensors(MachineStrategy s);
std::string ToString(MachineStrategy s);

/// Sources of the uncompensated lead error (accumulated over the thread, um, each alone).
enum class ErrorSource { kWorkpiece, kHead, kZScrew, kBed };
inline constexpr std::size_t kErrorSourceCount = 4;
std::string ToString(ErrorSource s);  ///< workpiece, head, z_screw, bed

struct MachineEvalOptions {
  machine::MachineConfig machine = machine::DefaultMachine();
  int machines = 2;                 ///< machines drawn (1..50)
  int screws_per_machine = 3;       ///< random screws per machine (1..200)
  int train_runs = 2;               ///< idle and cutting training runs per machine (1..20)
  std::uint64_t seed = 1;           ///< machines, days, screws and truths (see Seeds above)
  compare::CompareOptions compare;  ///< the workpiece comparison (plan, curve shape, metrics)
  drift::FitOptions fit;            ///< threads are forced to 1 (the screws run in parallel)
  int threads = 2;                  ///< worker threads (1..64)
  double monitor_every_min = 30;    ///< both_monitor: check interval, min (> 0)
  /// Non-empty: WriteMachineScrewReport of the first screw (machine 0) into this folder.
  std::string report_dir;
  /// With report_dir: the report also holds the combined 840D programs of that screw for this
  /// profile (machine_eval/machine_nc.h; shipped: datasets/machines/whirling_840d.json).
  std::optional<interp::MachineProfile> profile;
};

/// The machine models of one machine.
struct MachineModels {
  bool fitted = false;  ///< false when every machine component is off
  drift::DriftModel offset_cutting, slope_cutting, offset_idle, slope_idle;
  ShopModels shop;  ///< trained from the measured training runs only (history.h)
};

struct MachineEvalScrew {
  int machine = 0;
  int day = 0;              ///< field world: calendar day of the cut (legacy: 0)
  std::string start_type;   ///< field world: cold, warm, interrupted, long_pause (legacy: "")
  screw::Screw screw;
  std::uint64_t seed = 0, day_seed = 0;
  bool ok = false;
  std::string error;
  std::array<lead::LeadMetrics, kMachineStrategyCount> metrics;
  std::array<lead::IsoClass, kMachineStrategyCount> iso{};
  /// Uncompensated accumulated error over the thread of each source alone, um.
  std::array<double, kErrorSourceCount> source_total_um{};
  /// "both": accumulated error over the thread of the workpiece and machine residuals, um.
  double residual_workpiece_total_um = 0, residual_machine_total_um = 0;
};

struct MachineEvalSummary {
  std::size_t screws = 0, failed = 0;
  std::array<compare::AbsoluteStats, kMachineStrategyCount> absolute;
  std::array<double, kMachineStrategyCount> share_p3{}, share_p5{};
  std::array<double, kErrorSourceCount> source_median_um{};  ///< uncompensated, per source
  std::size_t residual_workpiece_dominates = 0, residual_machine_dominates = 0;
  std::string message;
};

struct MachineEvaluation {
  /// The strategies this evaluation scores (empty: every one, the legacy table).
  std::vector<MachineStrategy> rows;
  std::vector<std::vector<std::string>> sensors_cutting, sensors_idle;  ///< per machine
  std::vector<MachineEvalScrew> screws;
  MachineEvalSummary summary;
  std::string report_index;  ///< index.html of the report, when written
  /// Why the report holds no combined programs (a profile that does not fit the machine), or "".
  std::string programs_note;
};

/// Training runs of machine `machine_seed` (idle warm-ups then cutting runs).
std::vector<drift::Run> TrainingRuns(const machine::MachineConfig& config,
                                     std::uint64_t machine_seed, int runs, drift::RunState state);
MachineModels FitMachineModels(const machine::MachineConfig& config, std::uint64_t machine_seed,
                               int runs, const drift::FitOptions& fit);
/// The shop's measurement records of the same training runs (history.h), what ShopModels learn.
drift::ShopRecord ShopRecordOf(const machine::MachineConfig& config, std::uint64_t machine_seed,
                               int runs);

/// Curves of one screw, for the report: its sensor log and the lead deviation per strategy.
struct MachineScrewDetail {
  drift::Run log;  ///< empty when no machine model was fitted
  std::array<lead::LeadDeviation, kMachineStrategyCount> leads;
  fit::ArctanCurve predicted_curve;  ///< the network's curve (the workpiece plan's)
  screw::Kinematics kinematics;
};

/// One screw on one machine day (see the header comment); `detail` (optional) receives the curves.
MachineEvalScrew EvaluateScrewOnMachine(const screw::Screw& screw, const workpiece::WorkpieceModel& model,
                                        const compare::ExperienceRule& rule,
                                        const lead::IsoToleranceTable& iso_table,
                                        const machine::MachineDay& day, const MachineModels& models,
                                        const compare::CompareOptions& options,
                                        double monitor_every_min = 30,
                                        MachineScrewDetail* detail = nullptr);

MachineEvaluation EvaluateWithMachines(const screw::Screw& base, const workpiece::WorkpieceModel& model,
                                       const compare::ExperienceRule& rule,
                                       const lead::IsoToleranceTable& iso_table,
                                       const MachineEvalOptions& options,
                                       const compare::EvaluateProgress& progress = {});

MachineEvalSummary SummarizeMachineEval(const std::vector<MachineEvalScrew>& screws);
/// The rows of the legacy table: every strategy but lead_slope.
std::vector<MachineStrategy> LegacyStrategies();
/// The rows of an evaluation: `rows`, or the legacy table's when empty.
std::vector<MachineStrategy> RowsOf(const std::vector<MachineStrategy>& rows);
/// Fixed-width text table (strategy: median/worst um within 1000 mm and over the thread, P3/P5).
std::string FormatMachineEvalTable(const MachineEvaluation& e, bool markdown);

void to_json(nlohmann::json& j, const MachineEvaluation& e);

}  // namespace whirl::machine_eval
