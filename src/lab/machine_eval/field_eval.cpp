#include "machine_eval/field_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>

#include "core/curve.h"
#include "core/error.h"
#include "core/parallel.h"
#include "core/random.h"
#include "machine/truth.h"
#include "machine_eval/cut_scoring.h"
#include "machine_eval/strategies.h"

namespace whirl::machine_eval {

FieldMachineModels TrainFieldMachine(const machine::MachineTimeline& timeline,
                                     const FieldProtocol& protocol,
                                     const WorkpieceResidual& workpiece_residual,
                                     std::uint64_t seed) {
  FieldMachineModels m;
  const drift::ShopRecord record =
      FieldShopRecord(timeline, protocol, workpiece_residual, seed, &m.lead_slopes);
  m.z_ref_mm = timeline.machine().config().z.fixed_end_mm;
  m.shop = FitShopModels(record, m.z_ref_mm, ScheduleInputs(), protocol.grey_slope_lags_only,
                         protocol.grey_candidates, protocol.grey_five_sensors,
                         protocol.grey_short_mix);
  m.monitor = MakeProbeMonitor(m.shop.sensors, record.day_logs);
  m.control = ShopControlModels(m.shop.sensors, record.day_logs);
  if (m.shop.mix.computed)
    m.mix_rule_control = ShopControlModels(
        m.shop.rule_is_schedule ? m.shop.schedule : m.shop.warmup, record.day_logs);
  m.records = static_cast<int>(record.records.size());
  m.lead_days = static_cast<int>(drift::LeadDays(record).size());
  for (const auto& r : record.records) m.readings += static_cast<int>(r.rows.size());
  return m;
}

namespace {

using machine::CutRef;
using machine::Job;
using machine::MachineTimeline;

struct Workpiece {
  const workpiece::WorkpieceModel& model;
  const compare::ExperienceRule& rule;
  const lead::IsoToleranceTable& iso;
  const compare::CompareOptions& options;
};

// The workpiece comparison of a field cut: the blank starts at the hall's temperature through its
// lag and follows the hall's slope over the cut (one hall for the machine and the blank).
compare::ScrewComparison CompareFieldCut(const MachineTimeline& tl, const CutRef& cut,
                                         const Workpiece& wp) {
  const machine::DayPlan& plan = tl.Day(cut.day);
  const Job& job = plan.jobs[static_cast<std::size_t>(cut.job)];
  const machine::CutHall hall = machine::HallDuringCut(tl, cut);
  screw::Screw screw = job.screw;
  screw.settings.ambient_temperature_c = hall.start_c;
  compare::CompareOptions co = wp.options;
  co.disturbance.ambient_drift_fixed_k_per_h = hall.slope_k_per_h;
  co.seed = MixSeed(plan.seed, 0x77700 + static_cast<std::uint64_t>(cut.job));
  return compare::CompareScrew(screw, wp.model, wp.rule, wp.iso, co);
}

// The history screws were cut with the workpiece plan and no machine compensation: (e - c_wp)(t).
WorkpieceResidual HistoryResidual(const MachineTimeline& tl, const Workpiece& wp) {
  return [&tl, wp](const Job&, const CutRef& cut) -> std::function<double(double)> {
    try {
      const compare::ScrewComparison c = CompareFieldCut(tl, cut, wp);
      const compare::CompensationFunction plan =
          detail::Planned(c.plan, c.kinematics.axial_feed_mm_s);
      const ElongationCurve e = c.truth;
      return
          [e, plan](double t) { return InterpolateLinear(e.time_s, e.elongation_um, t) - plan(t); };
    } catch (const InputError&) {
      return nullptr;
    }
  };
}

// The screw of a test-day cut named for the pages and tables: its day, its place in the day and
// its type, e.g. "day 0 cut 2 (D 63.2 mm, lead 10.0 mm, 180 m/min)".
screw::Screw NamedCutScrew(const machine::Job& job, const CutRef& cut) {
  screw::Screw s = job.screw;
  const ProcessInputs& p = s.process;
  char buf[160];
  std::snprintf(buf, sizeof buf, "day %d cut %d (D %.1f mm, lead %.1f mm, %.0f m/min)", cut.day,
                cut.job + 1, p.diameter_mm, p.pitch_mm, p.cutting_speed_m_min);
  s.name = buf;
  return s;
}

// A part of the machine's truth along the cut at the workpiece truth's times (linear between the
// control samples).
ElongationCurve TruthCurve(const std::vector<machine::TruthSample>& m, double start_min,
                           const std::vector<double>& time_s,
                           double (*part)(const machine::TruthSample&)) {
  std::vector<double> at, value;
  for (const machine::TruthSample& s : m) at.push_back(s.abs_min), value.push_back(part(s));
  ElongationCurve c;
  c.time_s = time_s;
  for (double t : time_s)
    c.elongation_um.push_back(InterpolateLinear(at, value, start_min + t / 60.0));
  return c;
}

double TotalPart(const machine::TruthSample& s) { return s.total_um(); }
double HeadPart(const machine::TruthSample& s) { return s.head_um; }
double AxisPart(const machine::TruthSample& s) { return s.z_um + s.blank_um + s.extra_um; }

ElongationCurve Add(ElongationCurve a, const ElongationCurve& b) {
  for (std::size_t i = 0; i < a.size(); ++i) a.elongation_um[i] += b.elongation_um[i];
  return a;
}

// The shop models held sample by sample over the day's control log: sensors, warmup, schedule,
// the sensor model kept valid by the day's set-up checks, the grey box, and the opt-in rows
// (OptInRowName order; empty unless asked for).
struct DayHeld {
  HeldSamples sensors, warmup, schedule, monitored, grey;
  std::vector<HeldSamples> candidates;
};

// ReportScrew::sd_um of a cut: each strategy's compensation sd from its training data only.
std::array<double, kMachineStrategyCount> StrategySd(const compare::ScrewComparison& c,
                                                     const FieldMachineModels& models,
                                                     const compare::ExperienceRule& rule,
                                                     double thread_length_mm) {
  const auto both = [](double a, double b) { return std::hypot(a, b); };
  const double net = c.prediction.stddev.max_elongation_um;
  std::array<double, compare::kHistoryRuleCount> rules{};
  for (std::size_t k = 0; k < rules.size(); ++k)
    rules[k] = rule.has_choice ? rule.choice.loo_relative_error[k] *
                                     std::abs(c.history_features[k].max_elongation_um)
                               : 0.0;
  double mean = 0, var = 0;
  const auto& past = models.lead_slopes;
  for (const PastLeadSlope& p : past) mean += p.slope_um_per_m / static_cast<double>(past.size());
  for (const PastLeadSlope& p : past)
    var += (p.slope_um_per_m - mean) * (p.slope_um_per_m - mean) /
           static_cast<double>(std::max<std::size_t>(1, past.size() - 1));
  const double slope = std::sqrt(var) * thread_length_mm / 1000.0;
  const ShopModels& m = models.shop;
  return {0.0,
          rules[static_cast<std::size_t>(c.traditional_rule)],
          net,
          rules[0],
          rules[1],
          rules[2],
          both(net, m.warmup.cv_rmse_um),
          both(net, m.schedule.cv_rmse_um),
          both(net, slope),
          m.sensors.cv_rmse_um,
          both(net, m.sensors.cv_rmse_um),
          both(net, m.sensors.cv_rmse_um),
          both(net, m.grey.cv_rmse_um)};
}

// One test-day cut, every strategy; `report` (optional) receives its curves (the rest of the
// report screw is the caller's).
MachineEvalScrew EvaluateFieldCut(const MachineTimeline& tl, const CutRef& cut, const DayHeld& held,
                                  const FieldMachineModels& models, const Workpiece& wp,
                                  ReportScrew* report = nullptr) {
  const double z_ref_mm = models.z_ref_mm;
  const Job& job = tl.Day(cut.day).jobs[static_cast<std::size_t>(cut.job)];
  MachineEvalScrew out;
  out.screw = NamedCutScrew(job, cut);
  out.day = cut.day;
  out.start_type = machine::ToString(job.start_type);
  const compare::ScrewComparison c = CompareFieldCut(tl, cut, wp);
  out.seed = c.seed;
  const double start = cut.day * 1440.0 + job.cut_start_min;
  const std::vector<machine::TruthSample> m = machine::TrueCutError(tl, cut);
  const ElongationCurve machine_total = TruthCurve(m, start, c.truth.time_s, TotalPart);
  const ElongationCurve truth = Add(c.truth, machine_total);
  const double feed = c.kinematics.axial_feed_mm_s;
  const screw::Kinematics k = job.kinematics;
  auto line = [&](const HeldSamples& h) {
    return CausalMachineLine(h, start, z_ref_mm, [k](double t) {
      return k.thread_start_position_mm - k.axial_feed_mm_s * std::min(t, k.cutting_time_s);
    });
  };
  using detail::Planned;
  using detail::Sum;
  const compare::CompensationFunction workpiece = Planned(c.plan, feed);
  auto history = [&](const Features& f) {
    return Planned(detail::FeaturePlan(c, f, job.screw.thread_length_mm, wp.options), feed);
  };
  const compare::CompensationFunction none = compare::NoCompensation(), shop = line(held.sensors);
  const double b =
      LeadSlopeFor(models.lead_slopes, job.screw.process.diameter_mm, job.screw.process.pitch_mm);
  const compare::CompensationFunction lead_slope = [b, feed](double t) {
    return b * feed * t / 1000.0;
  };
  const std::array<compare::CompensationFunction, kMachineStrategyCount> comp = {
      none,                                 // none
      history(c.traditional_features),      // traditional
      workpiece,                            // workpiece
      history(c.history_features[0]),       // class
      history(c.history_features[1]),       // table
      history(c.history_features[2]),       // nearest
      Sum(workpiece, line(held.warmup)),    // warmup
      Sum(workpiece, line(held.schedule)),  // schedule
      Sum(workpiece, lead_slope),           // lead_slope
      shop,                                 // machine_shop
      Sum(workpiece, shop),                 // both_shop
      Sum(workpiece, line(held.monitored)),  // both_shop_monitor
      Sum(workpiece, line(held.grey))        // both_grey
  };
  detail::ScoreStrategies(truth, comp, feed, job.screw, wp.options, wp.iso, &out,
                          report ? &report->leads : nullptr);
  const std::size_t n = held.candidates.size();
  out.candidate_metrics.resize(n);
  out.candidate_iso.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    detail::ScoreOne(truth, Sum(workpiece, line(held.candidates[i])), feed, job.screw, wp.options,
                     wp.iso, &out.candidate_metrics[i], &out.candidate_iso[i]);
  if (report) {
    report->sd_um = StrategySd(c, models, wp.rule, job.screw.thread_length_mm);
    report->predicted_curve = c.predicted_curve;
    report->kinematics = c.kinematics;
    report->plan_options = wp.options.plan;
    report->cut_start_min = start;
    report->cut_end_min = start + k.cutting_time_s / 60.0;
  }
  const std::size_t sources[] = {0, 1, 2};
  const ElongationCurve parts[] = {c.truth, TruthCurve(m, start, c.truth.time_s, HeadPart),
                                   TruthCurve(m, start, c.truth.time_s, AxisPart)};
  for (std::size_t s : sources)
    out.source_total_um[s] = detail::TotalOf(parts[s], none, feed, job.screw, wp.options);
  out.residual_workpiece_total_um =
      detail::TotalOf(c.truth, workpiece, feed, job.screw, wp.options);
  out.residual_machine_total_um = detail::TotalOf(machine_total, shop, feed, job.screw, wp.options);
  out.ok = true;
  return out;
}

// The control's log from power-on to two samples after the cut (the report's sensor log).
drift::Run LogUpTo(const drift::Run& log, double end_min) {
  int n = 0;
  while (n < log.samples() && log.time_min[static_cast<std::size_t>(n)] <= end_min) ++n;
  return log.Slice(0, std::min(log.samples(), n + 2), log.name);
}

// The report screw's log, models and sensors (its curves come from EvaluateFieldCut); times from
// the day's 00:00.
void CompleteReport(const drift::Run& log, const FieldMachineModels& models, ReportScrew* r) {
  r->log = LogUpTo(log, r->cut_end_min);
  const double day_start = r->result.day * 1440.0;
  for (double& t : r->log.time_min) t -= day_start;
  r->cut_start_min -= day_start;
  r->cut_end_min -= day_start;
  r->sensor_model = models.shop.sensors;
  r->offset = models.control.offset;
  r->slope = models.control.slope;
  r->sensors = models.shop.sensors.sensors;
  r->sensors_choice = models.shop.sensors_choice;
  r->z_ref_mm = models.z_ref_mm;
  r->grey = models.shop.grey;
  const ShopModels& shop = models.shop;
  r->mix_computed = shop.mix.computed;
  r->mix_applied = shop.mix.applied;
  if (!r->mix_computed) return;
  r->mix_weight = shop.mix.fitted_weight;
  r->mix_rule_name = shop.rule_is_schedule ? "schedule" : "warmup";
  r->mix_rule = shop.rule_is_schedule ? shop.schedule : shop.warmup;
  r->mix_rule_offset = models.mix_rule_control.offset;
  r->mix_rule_slope = models.mix_rule_control.slope;
}

// Every test-day screw of one machine world; `report` (optional) receives the first screw that
// is evaluated without error.
std::vector<MachineEvalScrew> EvaluateTestDays(const MachineTimeline& tl,
                                               const FieldMachineModels& models,
                                               const FieldProtocol& protocol, const Workpiece& wp,
                                               int machine_index,
                                               std::optional<ReportScrew>* report = nullptr) {
  std::vector<MachineEvalScrew> out;
  MonitorState monitor;  // kept by the control from one test day to the next
  for (const machine::DayPlan& plan : tl.days()) {
    if (plan.day < 0) continue;
    const drift::Run log =
        AverageSensors(machine::ControlLog(tl, plan.day, MixSeed(plan.seed, 0x63746c)),
                       protocol.sensor_average_min);
    DayHeld held = {RunCausally(models.shop.sensors, log),
                    RunCausally(models.shop.warmup, log),
                    RunCausally(models.shop.schedule, log),
                    {},
                    RunCausally(models.shop.grey, log),
                    {}};
    const bool opt_in = protocol.offset_candidates || protocol.grey_candidates;
    for (std::size_t c = 0; opt_in && c < kOffsetCandidateCount; ++c)
      held.candidates.push_back(WithOffsetOf(
          held.grey, held.warmup, WarmupOffsetShare(static_cast<OffsetCandidate>(c))));
    for (const drift::GreyBoxModel& g : models.shop.grey_candidates)
      held.candidates.push_back(RunCausally(g, log));
    const ShopModels& shop = models.shop;
    if (shop.guard.chosen) {
      const HeldSamples& rule = shop.rule_is_schedule ? held.schedule : held.warmup;
      held.candidates.push_back(shop.guard.keep_grey ? held.grey : rule);
      for (double w : {shop.mix.fitted_weight, shop.mix.fixed_weight})
        held.candidates.push_back(MixedLines(held.grey, rule, w));
    }
    if (shop.mix.applied)  // both_grey's line is grey_short_mix's (after the rows built on the box)
      held.grey = MixedLines(held.grey, shop.rule_is_schedule ? held.schedule : held.warmup,
                             shop.mix.fitted_weight);
    const std::vector<machine::Reading> checks =
        machine::ProbeReadings(tl, SetupCheckTimes(plan), protocol.probe_z_mm,
                               protocol.probe_sigma_um, MixSeed(plan.seed, 0x6d6f6e));
    held.monitored = MonitorWithSetupChecks(held.sensors, models.monitor, log, checks,
                                            models.z_ref_mm, protocol.probe_z_mm,
                                            protocol.probe_sigma_um, protocol.monitor, &monitor)
                         .held;
    for (int j = 0; j < static_cast<int>(plan.jobs.size()); ++j) {
      MachineEvalScrew r;
      ReportScrew kept;
      const bool keep = report && !report->has_value();
      try {
        r = EvaluateFieldCut(tl, {plan.day, j}, held, models, wp, keep ? &kept : nullptr);
      } catch (const InputError& err) {
        r.screw = NamedCutScrew(plan.jobs[static_cast<std::size_t>(j)], {plan.day, j});
        r.day = plan.day;
        r.ok = false;
        r.error = err.what();
      }
      r.machine = machine_index;
      r.day_seed = plan.seed;
      if (keep && r.ok) {
        kept.result = r;
        CompleteReport(log, models, &kept);
        *report = std::move(kept);
      }
      out.push_back(std::move(r));
    }
  }
  return out;
}

void ValidateFieldOptions(const FieldEvalOptions& o) {
  const auto range = detail::CheckCount;
  range(o.machines, 1, 20, "machines");
  range(o.threads, 1, 64, "threads");
  range(o.calendar.test_days, 1, 20, "test days");
  range(o.calendar.past_days, 1, 40, "past days");
  o.machine.Validate("field machine '" + o.machine.name + "'");
}

}  // namespace

std::uint64_t ShopRecordSeed(std::uint64_t machine_seed) {
  return MixSeed(machine_seed, 0x73686f70);
}

WorkpieceResidual FieldHistoryResidual(const machine::MachineTimeline& timeline,
                                       const workpiece::WorkpieceModel& model,
                                       const compare::ExperienceRule& rule,
                                       const lead::IsoToleranceTable& iso_table,
                                       const compare::CompareOptions& options) {
  return HistoryResidual(timeline, Workpiece{model, rule, iso_table, options});
}

MachineEvaluation EvaluateFieldScenario(const machine::MachineScenario& scenario,
                                        const workpiece::WorkpieceModel& model,
                                        const compare::ExperienceRule& rule,
                                        const lead::IsoToleranceTable& iso_table,
                                        const FieldEvalOptions& options,
                                        const compare::EvaluateProgress& progress) {
  ValidateFieldOptions(options);
  const std::size_t n = static_cast<std::size_t>(options.machines);
  std::vector<std::vector<MachineEvalScrew>> per(n);
  std::vector<FieldMachineModels> models(n);
  const Workpiece wp{model, rule, iso_table, options.compare};
  std::optional<ReportScrew> report;
  ParallelFor(
      n, options.threads,
      [&](std::size_t i) {
        const machine::MachineWorld world =
            machine::BuildMachineWorld(options.machine, scenario, options.seed, static_cast<int>(i),
                                       options.calendar, options.timeline);
        models[i] =
            TrainFieldMachine(world.timeline, options.protocol, HistoryResidual(world.timeline, wp),
                              ShopRecordSeed(world.machine_seed));
        per[i] =
            EvaluateTestDays(world.timeline, models[i], options.protocol, wp, static_cast<int>(i),
                             i == 0 && options.keep_report_screw ? &report : nullptr);
      },
      progress);
  MachineEvaluation e;
  for (std::size_t i = 0; i < n; ++i) {
    e.sensors.push_back(models[i].shop.sensors.sensors);
    e.sensors_choice.push_back(models[i].shop.sensors_choice);
    const ShopModels& shop = models[i].shop;
    if (shop.guard.chosen)
      e.guard_choice.push_back(shop.guard.keep_grey      ? "both_grey"
                               : shop.rule_is_schedule ? "schedule"
                                                       : "warmup");
    if (shop.guard.chosen) e.short_mix_weight.push_back(shop.mix.fitted_weight);
    e.grey_fit.push_back({shop.grey.prior_strength, shop.grey.blank_tau_min,
                          shop.grey.cv_rmse_um, shop.grey.time_constants,
                          models[i].lead_days});
    e.screws.insert(e.screws.end(), per[i].begin(), per[i].end());
  }
  e.summary = SummarizeMachineEval(e.screws);
  e.summary.message = scenario.name + ", " + std::to_string(options.machines) +
                      (options.machines == 1 ? " machine: " : " machines: ") + e.summary.message;
  if (report) {
    report->scenario = scenario.name;
    e.report = std::move(report);
  }
  return e;
}

SeedsEvaluation EvaluateFieldOverSeeds(const machine::MachineScenario& scenario,
                                       const workpiece::WorkpieceModel& model,
                                       const compare::ExperienceRule& rule,
                                       const lead::IsoToleranceTable& iso_table,
                                       const FieldEvalOptions& options, int seeds,
                                       const compare::EvaluateProgress& progress) {
  detail::CheckCount(seeds, 1, 20, "seeds");
  SeedsEvaluation e;
  e.scenario = scenario.name;
  const std::size_t per = static_cast<std::size_t>(options.machines);
  for (int s = 0; s < seeds; ++s) {
    FieldEvalOptions o = options;
    o.seed = options.seed + static_cast<std::uint64_t>(s);
    o.keep_report_screw = options.keep_report_screw && s == 0;
    e.seeds.push_back(o.seed);
    e.runs.push_back(EvaluateFieldScenario(scenario, model, rule, iso_table, o,
                                           [&](std::size_t done, std::size_t) {
                                             if (progress) progress(s * per + done, seeds * per);
                                           }));
  }
  // The report screw's programs (summary.h ProgramsStrategy: the grey box where it was fitted).
  if (!e.runs.empty() && e.runs.front().report) {
    ReportScrew& r = *e.runs.front().report;
    r.programs_strategy =
        ProgramsStrategy(SummarizeOverSeeds(e), !r.grey.Inputs().empty(), &r.programs_reason);
  }
  return e;
}

std::vector<SeedsEvaluation> EvaluateMachineScenarios(
    const std::vector<machine::MachineScenario>& scenarios, const workpiece::WorkpieceModel& model,
    const compare::ExperienceRule& rule, const lead::IsoToleranceTable& iso_table,
    const FieldEvalOptions& options, int seeds, const compare::EvaluateProgress& progress) {
  std::vector<SeedsEvaluation> out;
  const std::size_t n = scenarios.size();
  for (std::size_t i = 0; i < n; ++i) {
    auto step = [&](std::size_t done, std::size_t total) {
      if (progress && total) progress(i * 1000 + 1000 * done / total, n * 1000);
    };
    FieldEvalOptions o = options;
    o.keep_report_screw = options.keep_report_screw && i == 0;
    out.push_back(EvaluateFieldOverSeeds(scenarios[i], model, rule, iso_table, o, seeds, step));
  }
  return out;
}

}  // namespace whirl::machine_eval
