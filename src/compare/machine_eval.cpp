#include "compare/machine_eval.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "compare/machine_nc.h"
#include "core/error.h"
#include "core/parallel.h"
#include "drift/monitor.h"
#include "sim/random.h"

namespace whirl::compare {

std::string ToString(MachineStrategy s) {
  static const char* kNames[] = {"none", "traditional", "workpiece",   "machine",
                                 "both", "both_idle",   "both_monitor"};
  return kNames[static_cast<int>(s)];
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
  return sim::MixSeed(machine_seed, 0x1000 + day);
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

double TotalOf(const ElongationCurve& truth, const CompensationFunction& comp, double feed,
               const sim::Screw& screw, const CompareOptions& options) {
  LeadMetricOptions mo = options.metrics;
  mo.lead_mm = screw.process.pitch_mm;
  const LeadDeviation lead = CutLeadDeviation(truth, comp, feed, screw.thread_length_mm,
                                              screw.process.pitch_mm, options.cut);
  return ComputeLeadMetrics(lead, mo).accumulated_total_um;
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
    sim::Rng rng(day_seed);
    spec.cutting_speed_m_min = 150 + 60 * rng.Uniform();
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
  const auto idle = TrainingRuns(config, machine_seed, runs, drift::RunState::kIdle);
  const auto cutting = TrainingRuns(config, machine_seed, runs, drift::RunState::kCutting);
  m.offset_cutting = drift::FitDriftModel(cutting, "offset_um", f).model;
  m.slope_cutting = drift::FitDriftModel(cutting, "zscrew_per_1000_um", f).model;
  m.offset_idle = drift::FitDriftModel(idle, "offset_um", f).model;
  m.slope_idle = drift::FitDriftModel(idle, "zscrew_per_1000_um", f).model;
  m.fitted = true;
  return m;
}

MachineEvalScrew EvaluateScrewOnMachine(const sim::Screw& screw, const workpiece::WorkpieceModel& model,
                                        const ExperienceRule& rule,
                                        const IsoToleranceTable& iso_table,
                                        const machine::MachineDay& day, const MachineModels& models,
                                        const CompareOptions& options, double monitor_every_min,
                                        MachineScrewDetail* detail) {
  MachineEvalScrew out;
  out.screw = screw;
  out.seed = options.seed;
  // One hall: the workpiece follows the same ambient ramp as the machine's bed.
  CompareOptions co = options;
  if (day.config.ambient.enabled)
    co.disturbance.ambient_drift_fixed_k_per_h = day.ambient_rate_k_per_h;
  const ScrewComparison c = CompareScrew(screw, model, rule, iso_table, co);
  if (detail) {
    detail->predicted_curve = c.predicted_curve;
    detail->kinematics = c.kinematics;
  }
  const double feed = c.kinematics.axial_feed_mm_s;
  const double z0 = c.kinematics.thread_start_position_mm;
  const double v_c = screw.process.cutting_speed_m_min;
  const double z_fixed = day.config.z_screw.fixed_end_mm;
  auto z_of = [&](double t_s) { return z0 - feed * std::min(t_s, c.kinematics.cutting_time_s); };

  // Truth: workpiece + machine; and each source alone.
  std::array<ElongationCurve, kErrorSourceCount> parts;
  ElongationCurve truth = c.truth, machine_truth;
  for (auto& p : parts) p.time_s = c.truth.time_s;
  machine_truth.time_s = c.truth.time_s;
  parts[0].elongation_um = c.truth.elongation_um;
  for (std::size_t i = 0; i < c.truth.size(); ++i) {
    const double t_min = c.truth.time_s[i] / 60.0, z = z_of(c.truth.time_s[i]);
    const double head = day.HeadUm(t_min, true, v_c);
    const double screw_um = day.ZScrewPer1000Um(t_min, true) * (z_fixed - z) / 1000.0;
    const double bed = day.BedUm(t_min);
    parts[1].elongation_um.push_back(head);
    parts[2].elongation_um.push_back(screw_um);
    parts[3].elongation_um.push_back(bed);
    const double m = head + screw_um + bed;
    machine_truth.elongation_um.push_back(m);
    truth.elongation_um[i] += m;
  }

  // Compensations.
  interp::CompensationPlan traditional_plan;
  const Features& tf = c.traditional_features;
  if (tf.max_elongation_um > 0 && tf.settle_time_s > 0)
    traditional_plan = interp::BuildPlan(
        fit::ArctanCurve::FromFeatures(tf, options.shape_k, options.time_exponent), feed,
        screw.thread_length_mm, options.plan);
  auto planned = [feed](const interp::CompensationPlan& plan) -> CompensationFunction {
    if (plan.segments.empty()) return NoCompensation();
    return [&plan, feed](double t_s) {
      return interp::AppliedCompensationUm(plan, interp::AxisPositionMm(plan.options, feed, t_s));
    };
  };
  const CompensationFunction wp = planned(c.plan), trad = planned(traditional_plan);
  CompensationFunction mach_cut = NoCompensation(), mach_idle = NoCompensation(),
                       mach_monitor = NoCompensation();
  if (models.fitted) {
    machine::RunSpec spec;
    spec.name = screw.name + "_log";
    spec.duration_min = c.kinematics.cutting_time_s / 60.0 + 2 * day.config.sample_min;
    spec.cutting_speed_m_min = v_c;
    spec.noise_seed = sim::MixSeed(options.seed, 77);
    const drift::Run log = machine::SimulateRun(day, spec);
    if (detail) detail->log = log;
    const double step = day.config.sample_min;
    auto held = [&](const drift::DriftModel& k0, const drift::DriftModel& g) {
      const HeldSeries a = Predict(k0, log, step), b = Predict(g, log, step);
      return CompensationFunction([a, b, z_of, z_fixed](double t) {
        return a.At(t) + b.At(t) * (z_fixed - z_of(t)) / 1e3;
      });
    };
    mach_cut = held(models.offset_cutting, models.slope_cutting);
    mach_idle = held(models.offset_idle, models.slope_idle);
    drift::MonitorOptions mo;
    mo.check_every = monitor_every_min;
    mo.refit_samples = 0;
    mo.noise_um = 0.5;
    mo.seed = options.seed;
    mo.rules = {drift::UpdateRule::kOffset};
    const drift::MonitorResult monitored = drift::MonitorRun(models.offset_cutting, log, mo);
    const Eigen::VectorXd& k0 = monitored.strategies.back().predicted_um;
    HeldSeries a{step, std::vector<double>(k0.data(), k0.data() + k0.size())};
    const HeldSeries b = Predict(models.slope_cutting, log, step);
    mach_monitor = [a, b, z_of, z_fixed](double t) {
      return a.At(t) + b.At(t) * (z_fixed - z_of(t)) / 1e3;
    };
  }
  auto sum = [](CompensationFunction a, CompensationFunction b) -> CompensationFunction {
    return [a, b](double t) { return a(t) + b(t); };
  };
  const std::array<CompensationFunction, kMachineStrategyCount> comp = {
      NoCompensation(),     trad, wp, mach_cut, sum(wp, mach_cut), sum(wp, mach_idle),
      sum(wp, mach_monitor)};

  LeadMetricOptions mo = options.metrics;
  mo.lead_mm = screw.process.pitch_mm;
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k) {
    const LeadDeviation lead = CutLeadDeviation(truth, comp[k], feed, screw.thread_length_mm,
                                                screw.process.pitch_mm, options.cut);
    out.metrics[k] = ComputeLeadMetrics(lead, mo);
    if (detail) detail->leads[k] = lead;
    out.iso[k] = EvaluateIsoClass(out.metrics[k], iso_table).reached;
  }
  for (std::size_t s = 0; s < kErrorSourceCount; ++s)
    out.source_total_um[s] = TotalOf(parts[s], NoCompensation(), feed, screw, options);
  out.residual_workpiece_total_um = TotalOf(c.truth, wp, feed, screw, options);
  out.residual_machine_total_um = TotalOf(machine_truth, mach_cut, feed, screw, options);
  out.ok = true;
  return out;
}

MachineEvaluation EvaluateWithMachines(const sim::Screw& base, const workpiece::WorkpieceModel& model,
                                       const ExperienceRule& rule,
                                       const IsoToleranceTable& iso_table,
                                       const MachineEvalOptions& options,
                                       const EvaluateProgress& progress) {
  auto range = [](int v, int lo, int hi, const char* what) {
    if (v < lo || v > hi)
      throw InputError(std::string(what) + " = " + std::to_string(v) + ": must be within " +
                       std::to_string(lo) + ".." + std::to_string(hi));
  };
  range(options.machines, 1, 50, "machines");
  range(options.screws_per_machine, 1, 200, "screws per machine");
  range(options.train_runs, 1, 20, "training runs");
  range(options.threads, 1, 64, "threads");
  options.machine.Validate("machine '" + options.machine.name + "'");
  const std::size_t n_machines = static_cast<std::size_t>(options.machines);
  std::vector<MachineModels> models(n_machines);
  std::vector<std::uint64_t> machine_seeds(n_machines);
  for (std::size_t i = 0; i < n_machines; ++i)
    machine_seeds[i] = sim::MixSeed(options.seed, 0x4d00 + i);
  ParallelFor(n_machines, options.threads, [&](std::size_t i) {
    models[i] =
        FitMachineModels(options.machine, machine_seeds[i], options.train_runs, options.fit);
  });
  MachineEvaluation e;
  for (const auto& m : models) {
    e.sensors_cutting.push_back(m.offset_cutting.sensors);
    e.sensors_idle.push_back(m.offset_idle.sensors);
  }
  const std::size_t per = static_cast<std::size_t>(options.screws_per_machine);
  const std::vector<sim::Screw> screws =
      RandomFeasibleScrews(base, static_cast<int>(per * n_machines), options.seed);
  e.screws.resize(screws.size());
  ParallelFor(
      screws.size(), options.threads,
      [&](std::size_t k) {
        const std::size_t i = k / per;
        const std::uint64_t day_seed = DaySeed(machine_seeds[i], k);
        const machine::MachineDay day =
            machine::MachineDay::Draw(options.machine, machine_seeds[i], day_seed);
        CompareOptions co = options.compare;
        co.seed = sim::MixSeed(options.seed, k);
        try {
          e.screws[k] = EvaluateScrewOnMachine(screws[k], model, rule, iso_table, day, models[i],
                                               co, options.monitor_every_min);
        } catch (const InputError& err) {
          e.screws[k].screw = screws[k];
          e.screws[k].ok = false;
          e.screws[k].error = err.what();
        }
        e.screws[k].machine = static_cast<int>(i);
        e.screws[k].day_seed = day_seed;
      },
      progress);
  e.summary = SummarizeMachineEval(e.screws);
  if (!options.report_dir.empty() && e.screws.front().ok) {
    // The first screw again, keeping its curves (same seeds: the same figures).
    const machine::MachineDay day =
        machine::MachineDay::Draw(options.machine, machine_seeds[0], e.screws.front().day_seed);
    CompareOptions co = options.compare;
    co.seed = e.screws.front().seed;
    MachineScrewDetail detail;
    const MachineEvalScrew first =
        EvaluateScrewOnMachine(screws.front(), model, rule, iso_table, day, models[0], co,
                               options.monitor_every_min, &detail);
    std::optional<CombinedPrograms> programs;
    if (options.profile && models[0].fitted) {
      try {
        programs = BuildCombinedPrograms(detail.predicted_curve, detail.kinematics,
                                         screws.front().thread_length_mm, co.plan, models[0],
                                         day.config, *options.profile,
                                         "network curve of screw " + screws.front().name);
      } catch (const InputError& err) {  // the evaluation stands; the page says why
        e.programs_note = std::string("combined 840D programs not written: ") + err.what();
      }
    }
    e.report_index = WriteMachineScrewReport(options.report_dir, first, detail,
                                             e.sensors_cutting[0], e.sensors_idle[0],
                                             programs ? &*programs : nullptr, e.programs_note);
  }
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
      const IsoClass c = r.iso[k];
      if (c == IsoClass::kP1 || c == IsoClass::kP3) ++p3[k];
      if (c == IsoClass::kP1 || c == IsoClass::kP3 || c == IsoClass::kP5) ++p5[k];
    }
    for (std::size_t q = 0; q < kErrorSourceCount; ++q) sources[q].push_back(r.source_total_um[q]);
    if (r.residual_workpiece_total_um >= r.residual_machine_total_um)
      ++s.residual_workpiece_dominates;
    else
      ++s.residual_machine_dominates;
  }
  auto median = [](std::vector<double> v) {
    return v.empty() ? 0.0 : Stats(std::move(v)).median_pct;
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
    const AbsoluteStats& a = s.absolute[k];
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
  for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
    strategies[ToString(static_cast<MachineStrategy>(k))] = {
        {"accumulated_1000_median_um", s.absolute[k].acc1000_median_um},
        {"accumulated_1000_worst_um", s.absolute[k].acc1000_worst_um},
        {"accumulated_total_median_um", s.absolute[k].total_median_um},
        {"accumulated_total_worst_um", s.absolute[k].total_worst_um},
        {"share_reaching_p3", s.share_p3[k]},
        {"share_reaching_p5", s.share_p5[k]}};
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
      for (std::size_t k = 0; k < kMachineStrategyCount; ++k)
        x["strategies"][ToString(static_cast<MachineStrategy>(k))] = {
            {"metrics", r.metrics[k]}, {"iso_class", ToString(r.iso[k])}};
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

}  // namespace whirl::compare
