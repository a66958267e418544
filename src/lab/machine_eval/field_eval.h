#pragma once
// The machine evaluation (machine_eval.h) of a field scenario (machine/scenarios.h: a machine as a
// thermal network living a shop's calendar), over seeds and over several scenarios. Every figure
// it gives is measured in the project's simulator only. It returns results and writes nothing.
//
// Protocol per machine of a scenario (machine/scenarios.h BuildMachineWorld): the calendar's
// warm-up tests, laser test and past production days (all before day 0) give the shop's
// measurement records (field_history.h: probe, laser, the measured leads of past screws cut with
// the workpiece plan and no machine compensation, set-up checks); the machine models learn from
// them only (history.h FitShopModels: warmup, schedule and the sensor model, one estimator,
// drift/joint.h). The test days (day >= 0) are scored: each screw of the day is cut with every
// strategy, its workpiece truth from the workpiece simulator (compare/compare.h CompareScrew; the
// blank starts at the hall's temperature through its lag and follows the hall's slope over the
// cut, machine/truth.h HallDuringCut), the machine's truth m(t, z) along the cut from
// machine/truth.h TrueCutError (head, Z axis, and the blank cut warm and measured at 20 degC). A
// machine model runs on the day's control log (machine/instruments.h ControlLog, 10 s) from
// power-on and is applied by zero-order hold of the latest sample at or before t
// (strategies.h): past samples only. The strategies: machine_eval.h (the checks' probe readings
// of both_shop_monitor are instruments, seeded per day).
// Seeds: machine i of seed S is MachineSeed(S, i) (machine/scenarios.h); the workpiece truth of
// job j on day d from MixSeed(DaySeed, 0x77700 + j): results do not depend on the thread count.
#include <cstdint>
#include <vector>

#include "compare/evaluate.h"
#include "machine/scenarios.h"
#include "machine_eval/field_history.h"
#include "machine_eval/field_monitor.h"
#include "machine_eval/machine_eval.h"
#include "machine_eval/shop_models.h"
#include "machine_eval/summary.h"

namespace whirl::machine_eval {

struct FieldEvalOptions {
  machine::FieldMachineConfig machine = machine::DefaultFieldMachine();
  machine::CalendarSpec calendar;  ///< past_days, test_days, warm-up and laser tests
  FieldProtocol protocol;
  machine::TimelineOptions timeline;  ///< control sample; verification hooks for tests
  int machines = 2;                   ///< machines per seed (1..20)
  std::uint64_t seed = 1;
  compare::CompareOptions compare;  ///< the workpiece comparison (plan, curve shape, metrics)
  int threads = 2;                  ///< worker threads over machines (1..64)
  /// Keep the first test-day screw of machine 0 (its curves, log and models) in the evaluation's
  /// `report` for the report module (machine_report/); over seeds and scenarios only the first
  /// seed of the first scenario keeps it.
  bool keep_report_screw = false;
};

/// What a machine's shop models learned, and from how much.
struct FieldMachineModels {
  ShopModels shop;
  int records = 0, readings = 0;
  int lead_days = 0;                       ///< calendar days with a lead record (drift::LeadDays)
  double z_ref_mm = 0;                     ///< reference of the slope (the Z screw's fixed bearing)
  std::vector<PastLeadSlope> lead_slopes;  ///< the lead-slope rule's past screws
  ProbeMonitor monitor;  ///< both_shop_monitor: the sensor model's offset channel and its ranges
  /// The sensor model as the drift action's offset and slope models (shop_models.h).
  ShopControl control;
  /// The base rule grey_short_mix mixes in (schedule or warmup: ShopModels::rule_is_schedule)
  /// as the drift action's models; only where the guard was chosen (the opt-in grey rows).
  ShopControl mix_rule_control;
};

/// The models of one machine world from its shop record (field_history.h) only.
FieldMachineModels TrainFieldMachine(const machine::MachineTimeline& timeline,
                                     const FieldProtocol& protocol,
                                     const WorkpieceResidual& workpiece_residual,
                                     std::uint64_t seed);

/// The seed of a machine's shop record (TrainFieldMachine's `seed` in the evaluation).
std::uint64_t ShopRecordSeed(std::uint64_t machine_seed);

/// The history screws' workpiece residual as the evaluation computes it (cut with the workpiece
/// plan and no machine compensation; the blank at its start temperature, machine/truth.h
/// HallDuringCut). Every reference must outlive the function.
WorkpieceResidual FieldHistoryResidual(const machine::MachineTimeline& timeline,
                                       const workpiece::WorkpieceModel& model,
                                       const compare::ExperienceRule& rule,
                                       const lead::IsoToleranceTable& iso_table,
                                       const compare::CompareOptions& options);

/// One seed of a field scenario: every test-day screw of every machine.
MachineEvaluation EvaluateFieldScenario(const machine::MachineScenario& scenario,
                                        const workpiece::WorkpieceModel& model,
                                        const compare::ExperienceRule& rule,
                                        const lead::IsoToleranceTable& iso_table,
                                        const FieldEvalOptions& options,
                                        const compare::EvaluateProgress& progress = {});

/// Seeds options.seed .. + seeds - 1 (1..20; InputError otherwise).
SeedsEvaluation EvaluateFieldOverSeeds(const machine::MachineScenario& scenario,
                                       const workpiece::WorkpieceModel& model,
                                       const compare::ExperienceRule& rule,
                                       const lead::IsoToleranceTable& iso_table,
                                       const FieldEvalOptions& options, int seeds,
                                       const compare::EvaluateProgress& progress = {});

/// Every selected scenario over seeds (EvaluateFieldOverSeeds); progress(done, n) counts
/// scenarios x 1000.
std::vector<SeedsEvaluation> EvaluateMachineScenarios(
    const std::vector<machine::MachineScenario>& scenarios, const workpiece::WorkpieceModel& model,
    const compare::ExperienceRule& rule, const lead::IsoToleranceTable& iso_table,
    const FieldEvalOptions& options, int seeds, const compare::EvaluateProgress& progress = {});

}  // namespace whirl::machine_eval
