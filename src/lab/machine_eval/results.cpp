#include "machine_eval/machine_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/parallel.h"
#include "core/random.h"
#include "drift/monitor.h"
#include "machine_eval/machine_report.h"
#include "machine_eval/cut_scoring.h"
#include "machine_eval/strategies.h"

namespace whirl::machine_eval {

using detail::FeaturePlan;
using detail::Planned;
using detail::ScoreStrategies;
using detail::Sum;
using detail::TotalOf;

std::string ToString(MachineStrategy s) {
  static const char* kNames[] = {"none",        "traditional", "workpiece",    "machine",
                                 "both",        "both_idle",   "both_monitor", "class",
                                 "table",       "nearest",     "warmup",       "schedule",
                                 "machine_shop", "both_shop",  "lead_slope",   "both_shop_monitor"};
  return kNames[static_cast<int>(s)];
}

bool UsesSensors(MachineStrategy s) {
  switch (s) {
    case MachineStrategy::kMachine:
    case MachineStrategy::kBoth:
    case MachineStrategy::kBothIdle:
    case MachineStrategy::kBothMonitor:
    case MachineStrategy::kMachineShop:
    case MachineStrategy::kBothShop:
    case MachineStrategy::kBothShopMonitor:
      return true;
    default:
      return false;
  }
}

std::vector<MachineStrategy> LegacyStrategies() {
  std::vector<MachineStrategy> all;
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    if (static_cast<MachineStrategy>(k) != MachineStrategy::kLeadSlope &&
        static_cast<MachineStrategy>(k) != MachineStrategy::kBothShopMonitor)
      all.push_back(static_cast<MachineStrategy>(k));
  return all;
}

std::vector<MachineStrategy> RowsOf(const std::vector<MachineStrategy>& rows) {
  return rows.empty() ? LegacyStrategies() : rows;
}

std::string ToString(ErrorSource s) {
  static const char* kNames[] = {"workpiece", "head", "z_screw", "bed"};
  return kNames[static_cast<int>(s)];
}

namespace {

bool AnyMachineComponent(const machine::MachineConfig& c) {
  return c.head.enabled || c.z_screw.enabled || c.ambient.enabled;
}

std::uint64_t DaySeed(std::uint64_t machine_seed, std::uint64_t day) {
  return MixSeed(machine_seed, 0x1000 + day);
}

// Cutting speed of a training run, m/min, drawn from its day seed.
double TrainingSpeed(std::uint64_t day_seed) {
  Rng rng(day_seed);
  return 150 + 60 * rng.Uniform();
}

// Model predictions on a run, linearly interpolated between the samples (the control evaluates
// the model every interpolation cycle from analog inputs read continuously; the run's samples are
// the log's resolution), held after the last sample: value at time t_s.
struct HeldSeries {
  double step_min = 1;
  std::vector<double> values;
  double At(double t_s) const {
    if (values.empty()) return 0.0;
    const double u = std::max(0.0, t_s / 60.0 / step_min);
    const auto k = static_cast<std::size_t>(std::floor(u));
    if (k + 1 >= values.size()) return values.back();
    const double f = u - static_cast<double>(k);
    return (1 - f) * values[k] + f * values[k + 1];
  }
};

HeldSeries Predict(const drift::DriftModel& model, const drift::Run& run, double step_min) {
  const drift::RunPrediction p = drift::PredictRun(model, run);
  HeldSeries h;
  h.step_min = step_min;
  h.values.assign(p.predicted_um.data(), p.predicted_um.data() + p.predicted_um.size());
  return h;
}

}  // namespace

std::vector<drift::Run> TrainingRuns(const machine::MachineConfig& config,
                                     std::uint64_t machine_seed, int runs, drift::RunState state) {
  std::vector<drift::Run> out;
  const bool cutting = state == drift::RunState::kCutting;
  for (int r = 0; r < runs; ++r) {
    const std::uint64_t day_seed = DaySeed(machine_seed, (cutting ? 100 : 200) + r);
    const machine::MachineDay day = machine::MachineDay::Draw(config, machine_seed, day_seed);
    machine::RunSpec spec;
    spec.name = std::string(cutting ? "cutting_" : "idle_") + std::to_string(r + 1);
    spec.state = state;
    spec.duration_min = cutting ? 150 : 180;
    spec.cutting_speed_m_min = TrainingSpeed(day_seed);
    spec.noise_seed = day_seed;
    out.push_back(machine::SimulateRun(day, spec));
  }
  return out;
}

MachineModels FitMachineModels(const machine::MachineConfig& config, std::uint64_t machine_seed,
                               int runs, const drift::FitOptions& fit) {
  MachineModels m;
  if (!AnyMachineComponent(config)) return m;
  drift::FitOptions f = fit;
  f.threads = 1;
  // The sensor models as documented: no time-only candidate, errors as the simulator logs them.
  f.candidates = drift::Candidates::kSensors;
  f.zero.zero = drift::ErrorZero::kAsLogged;
  const auto idle = TrainingRuns(config, machine_seed, runs, drift::RunState::kIdle);
  const auto cutting = TrainingRuns(config, machine_seed, runs, drift::RunState::kCutting);
  m.offset_cutting = drift::FitDriftModel(cutting, "offset_um", f).model;
  m.slope_cutting = drift::FitDriftModel(cutting, "zscrew_per_1000_um", f).model;
  m.offset_idle = drift::FitDriftModel(idle, "offset_um", f).model;
  m.slope_idle = drift::FitDriftModel(idle, "zscrew_per_1000_um", f).model;
  m.shop = FitShopModels(ShopRecordOf(config, machine_seed, runs), config.z_screw.fixed_end_mm);
  m.fitted = true;
  return m;
}

drift::ShopRecord ShopRecordOf(const machine::MachineConfig& config, std::uint64_t machine_seed,
                               int runs) {
  std::vector<drift::Run> all = TrainingRuns(config, machine_seed, runs, drift::RunState::kIdle);
  const auto cutting = TrainingRuns(config, machine_seed, runs, drift::RunState::kCutting);
  std::vector<double> speeds(all.size(), 0.0);
  for (int r = 0; r < runs; ++r) speeds.push_back(TrainingSpeed(DaySeed(machine_seed, 100 + r)));
  all.insert(all.end(), cutting.begin(), cutting.end());
  return MeasureTrainingRuns(all, speeds, config.z_screw.fixed_end_mm, ShopProtocol{},
                             MixSeed(machine_seed, 0x73686f70));
}

namespace {

// Where the tool is during the cut: z(t) = z_0 - v_f min(t, t_cut) [mm from the chuck face], and
// the Z screw's fixed bearing z_fixed.
struct ToolPath {
  double feed_mm_s = 0, start_mm = 0, cutting_time_s = 0, fixed_end_mm = 0;
  double ZAt(double t_s) const { return start_mm - feed_mm_s * std::min(t_s, cutting_time_s); }
};

ToolPath PathOf(const screw::Kinematics& k, const machine::MachineDay& day) {
  return {k.axial_feed_mm_s, k.thread_start_position_mm, k.cutting_time_s,
          day.config.z_screw.fixed_end_mm};
}

// The workpiece's comparison on this machine's day. One hall: with the machine's ambient
// component on, the blank follows the day's ambient ramp, the one the bed follows.
compare::ScrewComparison CompareOnDay(const screw::Screw& screw, const workpiece::WorkpieceModel& model,
                                      const compare::ExperienceRule& rule,
                                      const lead::IsoToleranceTable& iso_table,
                                      const machine::MachineDay& day,
                                      const compare::CompareOptions& options) {
  compare::CompareOptions co = options;
  if (day.config.ambient.enabled)
    co.disturbance.ambient_drift_fixed_k_per_h = day.ambient_rate_k_per_h;
  return compare::CompareScrew(screw, model, rule, iso_table, co);
}

// The truth of the cut, e + m, and its parts: the workpiece e and the machine's head, Z screw and
// bed at the tool position (ErrorSource order), and m alone.
struct TruthOnMachine {
  std::array<ElongationCurve, kErrorSourceCount> parts;
  ElongationCurve total, machine;
};

TruthOnMachine TruthWithMachine(const ElongationCurve& workpiece, const machine::MachineDay& day,
                                const ToolPath& path, double cutting_speed_m_min) {
  TruthOnMachine t;
  t.total = workpiece;
  for (auto& p : t.parts) p.time_s = workpiece.time_s;
  t.machine.time_s = workpiece.time_s;
  t.parts[0].elongation_um = workpiece.elongation_um;
  for (std::size_t i = 0; i < workpiece.size(); ++i) {
    const double t_min = workpiece.time_s[i] / 60.0, z = path.ZAt(workpiece.time_s[i]);
    const double head = day.HeadUm(t_min, true, cutting_speed_m_min);
    const double screw_um = day.ZScrewPer1000Um(t_min, true) * (path.fixed_end_mm - z) / 1000.0;
    const double bed = day.BedUm(t_min);
    t.parts[1].elongation_um.push_back(head);
    t.parts[2].elongation_um.push_back(screw_um);
    t.parts[3].elongation_um.push_back(bed);
    const double m = head + screw_um + bed;
    t.machine.elongation_um.push_back(m);
    t.total.elongation_um[i] += m;
  }
  return t;
}

// The machine line c_m(t) = K0(t) + G(t) (z_fixed - z(t)) / 1000 from the offset and slope
// predictions.
compare::CompensationFunction MachineLine(const HeldSeries& offset, const HeldSeries& slope,
                                          const ToolPath& path) {
  return [offset, slope, path](double t) {
    return offset.At(t) + slope.At(t) * (path.fixed_end_mm - path.ZAt(t)) / 1e3;
  };
}

// The screw's own sensor log: the machine's day over the cut and two samples more.
drift::Run ScrewSensorLog(const machine::MachineDay& day, const screw::Screw& screw,
                          const screw::Kinematics& kinematics, std::uint64_t seed) {
  machine::RunSpec spec;
  spec.name = screw.name + "_log";
  spec.duration_min = kinematics.cutting_time_s / 60.0 + 2 * day.config.sample_min;
  spec.cutting_speed_m_min = screw.process.cutting_speed_m_min;
  spec.noise_seed = MixSeed(seed, 77);
  return machine::SimulateRun(day, spec);
}

// The cutting-trained offset model kept valid by the check bar (drift/monitor.h MonitorRun, rule
// offset from the invalid check alone, 0.5 um noise): its prediction on the log.
HeldSeries MonitoredOffset(const drift::DriftModel& offset, const drift::Run& log, double every_min,
                           std::uint64_t seed, double step_min) {
  drift::MonitorOptions mo;
  mo.check_every = every_min;
  mo.refit_samples = 0;
  mo.noise_um = 0.5;
  mo.seed = seed;
  mo.rules = {drift::UpdateRule::kOffset};
  const drift::MonitorResult monitored = drift::MonitorRun(offset, log, mo);
  const Eigen::VectorXd& k0 = monitored.strategies.back().predicted_um;
  return {step_min, std::vector<double>(k0.data(), k0.data() + k0.size())};
}

// The machine models' compensations on the screw's log: trained cutting, trained idle, and the
// cutting-trained one with the check bar; none when no model was fitted.
struct MachineCompensations {
  compare::CompensationFunction cutting = compare::NoCompensation(),
                                idle = compare::NoCompensation(),
                                monitored = compare::NoCompensation();
  drift::Run log;
  /// Trained from measurements only, applied causally (strategies.h).
  compare::CompensationFunction shop = compare::NoCompensation(),
                                warmup = compare::NoCompensation(),
                                schedule = compare::NoCompensation();
};

// The shop-trained models on the control's log of the cut (its first row is the cold start, the
// legacy world's power-on), each held sample by sample.
void ShopCompensations(const MachineModels& models, const screw::Screw& screw, const ToolPath& path,
                       MachineCompensations* m) {
  const drift::Run control = ControlDayLog(m->log, screw.process.cutting_speed_m_min);
  auto line = [&](const drift::JointDriftModel& model) {
    return CausalMachineLine(RunCausally(model, control), 0.0, path.fixed_end_mm,
                             [path](double t) { return path.ZAt(t); });
  };
  m->shop = line(models.shop.sensors);
  m->warmup = line(models.shop.warmup);
  m->schedule = line(models.shop.schedule);
}

MachineCompensations MachineModelCompensations(const MachineModels& models,
                                               const machine::MachineDay& day,
                                               const screw::Screw& screw,
                                               const screw::Kinematics& kinematics,
                                               const ToolPath& path, std::uint64_t seed,
                                               double monitor_every_min) {
  MachineCompensations m;
  if (!models.fitted) return m;
  m.log = ScrewSensorLog(day, screw, kinematics, seed);
  const double step = day.config.sample_min;
  const HeldSeries slope_cutting = Predict(models.slope_cutting, m.log, step);
  m.cutting = MachineLine(Predict(models.offset_cutting, m.log, step), slope_cutting, path);
  m.idle = MachineLine(Predict(models.offset_idle, m.log, step),
                       Predict(models.slope_idle, m.log, step), path);
  m.monitored =
      MachineLine(MonitoredOffset(models.offset_cutting, m.log, monitor_every_min, seed, step),
                  slope_cutting, path);
  ShopCompensations(models, screw, path, &m);
  return m;
}

}  // namespace

MachineEvalScrew EvaluateScrewOnMachine(const screw::Screw& screw, const workpiece::WorkpieceModel& model,
                                        const compare::ExperienceRule& rule,
                                        const lead::IsoToleranceTable& iso_table,
                                        const machine::MachineDay& day, const MachineModels& models,
                                        const compare::CompareOptions& options,
                                        double monitor_every_min, MachineScrewDetail* detail) {
  MachineEvalScrew out;
  out.screw = screw;
  out.seed = options.seed;
  const compare::ScrewComparison c = CompareOnDay(screw, model, rule, iso_table, day, options);
  const ToolPath path = PathOf(c.kinematics, day);
  const double feed = path.feed_mm_s;
  const TruthOnMachine truth =
      TruthWithMachine(c.truth, day, path, screw.process.cutting_speed_m_min);
  const compare::CompensationFunction workpiece = Planned(c.plan, feed);
  MachineCompensations machine = MachineModelCompensations(models, day, screw, c.kinematics, path,
                                                           options.seed, monitor_every_min);
  auto history = [&](const Features& f) {
    return Planned(FeaturePlan(c, f, screw.thread_length_mm, options), feed);
  };
  const std::array<compare::CompensationFunction, kMachineStrategyCount> compensations = {
      compare::NoCompensation(),
      history(c.traditional_features),
      workpiece,
      machine.cutting,
      Sum(workpiece, machine.cutting),
      Sum(workpiece, machine.idle),
      Sum(workpiece, machine.monitored),
      history(c.history_features[0]),
      history(c.history_features[1]),
      history(c.history_features[2]),
      Sum(workpiece, machine.warmup),
      Sum(workpiece, machine.schedule),
      machine.shop,
      Sum(workpiece, machine.shop),
      workpiece,
      Sum(workpiece, machine.shop)};  // lead_slope and both_shop_monitor: not legacy rows
  ScoreStrategies(truth.total, compensations, feed, screw, options, iso_table, &out, detail);
  for (std::size_t s = 0; s < kErrorSourceCount; ++s)
    out.source_total_um[s] =
        TotalOf(truth.parts[s], compare::NoCompensation(), feed, screw, options);
  out.residual_workpiece_total_um = TotalOf(c.truth, workpiece, feed, screw, options);
  out.residual_machine_total_um = TotalOf(truth.machine, machine.cutting, feed, screw, options);
  if (detail) {
    detail->predicted_curve = c.predicted_curve;
    detail->kinematics = c.kinematics;
    detail->log = std::move(machine.log);
  }
  out.ok = true;
  return out;
}

namespace {

void ValidateMachineEvalOptions(const MachineEvalOptions& options) {
  const auto range = detail::CheckCount;
  range(options.machines, 1, 50, "machines");
  range(options.screws_per_machine, 1, 200, "screws per machine");
  range(options.train_runs, 1, 20, "training runs");
  range(options.threads, 1, 64, "threads");
  options.machine.Validate("machine '" + options.machine.name + "'");
}

// The drawn machines: their seeds and drift models, fitted in parallel.
struct Machines {
  std::vector<std::uint64_t> seeds;
  std::vector<MachineModels> models;
};

Machines FitMachines(const MachineEvalOptions& options) {
  const std::size_t n = static_cast<std::size_t>(options.machines);
  Machines m;
  m.models.resize(n);
  for (std::size_t i = 0; i < n; ++i) m.seeds.push_back(MixSeed(options.seed, 0x4d00 + i));
  ParallelFor(n, options.threads, [&](std::size_t i) {
    m.models[i] = FitMachineModels(options.machine, m.seeds[i], options.train_runs, options.fit);
  });
  return m;
}

// Screw k is cut on machine k / screws_per_machine, on its own day, with its own truth seed; a
// screw whose comparison fails is kept with its error.
std::vector<MachineEvalScrew> EvaluateScrewsOnMachines(
    const std::vector<screw::Screw>& screws, const Machines& machines, const workpiece::WorkpieceModel& model,
    const compare::ExperienceRule& rule, const lead::IsoToleranceTable& iso_table,
    const MachineEvalOptions& options, const compare::EvaluateProgress& progress) {
  const std::size_t per = static_cast<std::size_t>(options.screws_per_machine);
  std::vector<MachineEvalScrew> out(screws.size());
  ParallelFor(
      screws.size(), options.threads,
      [&](std::size_t k) {
        const std::size_t i = k / per;
        const std::uint64_t day_seed = DaySeed(machines.seeds[i], k);
        const machine::MachineDay day =
            machine::MachineDay::Draw(options.machine, machines.seeds[i], day_seed);
        compare::CompareOptions co = options.compare;
        co.seed = MixSeed(options.seed, k);
        try {
          out[k] = EvaluateScrewOnMachine(screws[k], model, rule, iso_table, day,
                                          machines.models[i], co, options.monitor_every_min);
        } catch (const InputError& err) {
          out[k].screw = screws[k];
          out[k].ok = false;
          out[k].error = err.what();
        }
        out[k].machine = static_cast<int>(i);
        out[k].day_seed = day_seed;
      },
      progress);
  return out;
}

// The first screw again, keeping its curves (same seeds: the same figures), and its report with
// the combined programs for options.profile; a profile that does not fit the machine leaves the
// programs out with a note (the evaluation stands).
void WriteFirstScrewReport(const screw::Screw& screw, const Machines& machines,
                           const workpiece::WorkpieceModel& model, const compare::ExperienceRule& rule,
                           const lead::IsoToleranceTable& iso_table,
                           const MachineEvalOptions& options, MachineEvaluation* e) {
  const machine::MachineDay day =
      machine::MachineDay::Draw(options.machine, machines.seeds[0], e->screws.front().day_seed);
  compare::CompareOptions co = options.compare;
  co.seed = e->screws.front().seed;
  MachineScrewDetail detail;
  const MachineEvalScrew first =
      EvaluateScrewOnMachine(screw, model, rule, iso_table, day, machines.models[0], co,
                             options.monitor_every_min, &detail);
  std::optional<CombinedPrograms> programs;
  if (options.profile && machines.models[0].fitted) {
    try {
      programs = BuildCombinedPrograms(
          detail.predicted_curve, detail.kinematics, screw.thread_length_mm, co.plan,
          machines.models[0], day.config, *options.profile, "network curve of screw " + screw.name);
    } catch (const InputError& err) {
      e->programs_note = std::string("combined 840D programs not written: ") + err.what();
    }
  }
  e->report_index = WriteMachineScrewReport(options.report_dir, first, detail,
                                            e->sensors_cutting[0], e->sensors_idle[0],
                                            programs ? &*programs : nullptr, e->programs_note);
}

}  // namespace

MachineEvaluation EvaluateWithMachines(const screw::Screw& base, const workpiece::WorkpieceModel& model,
                                       const compare::ExperienceRule& rule,
                                       const lead::IsoToleranceTable& iso_table,
                                       const MachineEvalOptions& options,
                                       const compare::EvaluateProgress& progress) {
  ValidateMachineEvalOptions(options);
  const Machines machines = FitMachines(options);
  MachineEvaluation e;
  for (const auto& m : machines.models) {
    e.sensors_cutting.push_back(m.offset_cutting.sensors);
    e.sensors_idle.push_back(m.offset_idle.sensors);
  }
  const std::vector<screw::Screw> screws = compare::RandomFeasibleScrews(
      base, options.screws_per_machine * options.machines, options.seed);
  e.screws = EvaluateScrewsOnMachines(screws, machines, model, rule, iso_table, options, progress);
  e.summary = SummarizeMachineEval(e.screws);
  if (!options.report_dir.empty() && e.screws.front().ok)
    WriteFirstScrewReport(screws.front(), machines, model, rule, iso_table, options, &e);
  return e;
}

MachineEvalSummary SummarizeMachineEval(const std::vector<MachineEvalScrew>& screws) {
  MachineEvalSummary s;
  s.screws = screws.size();
  std::array<std::vector<double>, kMachineStrategyCount> acc, total;
  std::array<std::vector<double>, kErrorSourceCount> sources;
  std::array<std::size_t, kMachineStrategyCount> p3{}, p5{};
  std::size_t ok = 0;
  for (const auto& r : screws) {
    if (!r.ok) {
      ++s.failed;
      continue;
    }
    ++ok;
    for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
      acc[k].push_back(std::abs(r.metrics[k].accumulated_1000_um));
      total[k].push_back(std::abs(r.metrics[k].accumulated_total_um));
      const lead::IsoClass c = r.iso[k];
      if (c == lead::IsoClass::kP1 || c == lead::IsoClass::kP3) ++p3[k];
      if (c == lead::IsoClass::kP1 || c == lead::IsoClass::kP3 || c == lead::IsoClass::kP5)
        ++p5[k];
    }
    for (std::size_t q = 0; q < kErrorSourceCount; ++q) sources[q].push_back(r.source_total_um[q]);
    if (r.residual_workpiece_total_um >= r.residual_machine_total_um)
      ++s.residual_workpiece_dominates;
    else
      ++s.residual_machine_dominates;
  }
  auto median = [](std::vector<double> v) {
    return v.empty() ? 0.0 : compare::Stats(std::move(v)).median_pct;
  };
  auto worst = [](const std::vector<double>& v) {
    return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end());
  };
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    s.absolute[k] = {median(acc[k]), worst(acc[k]), median(total[k]), worst(total[k])};
    s.share_p3[k] = ok ? static_cast<double>(p3[k]) / ok : 0.0;
    s.share_p5[k] = ok ? static_cast<double>(p5[k]) / ok : 0.0;
  }
  for (std::size_t q = 0; q < kErrorSourceCount; ++q) s.source_median_um[q] = median(sources[q]);
  char buf[512];
  std::snprintf(
      buf, sizeof buf,
      "%zu screws (%zu failed): within 1000 mm median none %.1f, traditional %.1f, "
      "workpiece %.1f, machine %.1f, both %.1f, both_idle %.1f, both_monitor %.1f um; "
      "what is left after both is dominated by the %s part in %zu of %zu screws",
      s.screws, s.failed, s.absolute[0].acc1000_median_um, s.absolute[1].acc1000_median_um,
      s.absolute[2].acc1000_median_um, s.absolute[3].acc1000_median_um,
      s.absolute[4].acc1000_median_um, s.absolute[5].acc1000_median_um,
      s.absolute[6].acc1000_median_um,
      s.residual_machine_dominates > s.residual_workpiece_dominates ? "machine" : "workpiece",
      std::max(s.residual_machine_dominates, s.residual_workpiece_dominates), ok);
  s.message = buf;
  return s;
}

std::string FormatMachineEvalTable(const MachineEvaluation& e, bool markdown) {
  const MachineEvalSummary& s = e.summary;
  std::string out;
  char buf[256];
  if (markdown)
    out +=
        "| strategy | 1000 mm median um | 1000 mm worst um | thread median um | thread worst um "
        "| P3 share | P5 share |\n|---|---|---|---|---|---|---|\n";
  else
    out += "strategy      1000mm med  worst  thread med  worst   P3    P5\n";
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    const compare::AbsoluteStats& a = s.absolute[k];
    const char* fmt = markdown ? "| %s | %.1f | %.1f | %.1f | %.1f | %.2f | %.2f |\n"
                               : "%-12s %9.1f %6.1f %11.1f %6.1f %5.2f %5.2f\n";
    std::snprintf(buf, sizeof buf, fmt, ToString(static_cast<MachineStrategy>(k)).c_str(),
                  a.acc1000_median_um, a.acc1000_worst_um, a.total_median_um, a.total_worst_um,
                  s.share_p3[k], s.share_p5[k]);
    out += buf;
  }
  out += markdown ? "\nUncompensated error over the thread by source alone, median um:"
                  : "uncompensated, over the thread, each source alone, median um:";
  for (std::size_t q = 0; q < kErrorSourceCount; ++q) {
    std::snprintf(buf, sizeof buf, " %s %.1f", ToString(static_cast<ErrorSource>(q)).c_str(),
                  s.source_median_um[q]);
    out += buf;
  }
  out += "\n";
  return out;
}

void to_json(nlohmann::json& j, const MachineEvaluation& e) {
  const MachineEvalSummary& s = e.summary;
  nlohmann::json strategies = nlohmann::json::object(), sources = nlohmann::json::object();
  for (MachineStrategy st : RowsOf(e.rows)) {
    const auto k = static_cast<std::size_t>(st);
    strategies[ToString(st)] = {
        {"accumulated_1000_median_um", s.absolute[k].acc1000_median_um},
        {"accumulated_1000_worst_um", s.absolute[k].acc1000_worst_um},
        {"accumulated_total_median_um", s.absolute[k].total_median_um},
        {"accumulated_total_worst_um", s.absolute[k].total_worst_um},
        {"share_reaching_p3", s.share_p3[k]},
        {"share_reaching_p5", s.share_p5[k]}};
  }
  for (std::size_t q = 0; q < kErrorSourceCount; ++q)
    sources[ToString(static_cast<ErrorSource>(q))] = s.source_median_um[q];
  nlohmann::json screws = nlohmann::json::array();
  for (const auto& r : e.screws) {
    nlohmann::json x = {{"name", r.screw.name},
                        {"machine", r.machine},
                        {"seed", r.seed},
                        {"day_seed", r.day_seed},
                        {"ok", r.ok}};
    if (!r.ok) {
      x["error"] = r.error;
    } else {
      for (MachineStrategy st : RowsOf(e.rows)) {
        const auto k = static_cast<std::size_t>(st);
        x["strategies"][ToString(st)] = {{"metrics", r.metrics[k]},
                                         {"iso_class", ToString(r.iso[k])}};
      }
      if (!r.start_type.empty()) x["day"] = r.day, x["start_type"] = r.start_type;
      x["residual_workpiece_total_um"] = r.residual_workpiece_total_um;
      x["residual_machine_total_um"] = r.residual_machine_total_um;
    }
    screws.push_back(x);
  }
  j = {{"schema", "whirl.machine_evaluate"},
       {"schema_version", 1},
       {"summary",
        {{"screws", s.screws},
         {"failed", s.failed},
         {"strategies", strategies},
         {"uncompensated_total_by_source_median_um", sources},
         {"residual_after_both_dominated_by_workpiece", s.residual_workpiece_dominates},
         {"residual_after_both_dominated_by_machine", s.residual_machine_dominates},
         {"message", s.message}}},
       {"machine_sensors_cutting_trained", e.sensors_cutting},
       {"machine_sensors_idle_trained", e.sensors_idle},
       {"screws", screws}};
}

}  // namespace whirl::machine_eval
