// Development driver (not installed, not a test): the choice of `drift fit` between the sensor
// model and the elapsed-time models (drift/fit.h ChooseCandidate) on planted logs, scored against
// the better of `--candidates sensors` and `--candidates time` case by case (issue 38's measure).
//   choice_study tuning [--seeds N]        the tuning set: tests/drift/planted_logs.h
//   choice_study confirmation [--seeds N]  the confirmation set: other generators, the field
//                                          machine (src/lab/machine/field.h) on production days
//                                          refitted daily and its warm-up tests (the closed-form
//                                          machine's warm-up runs of issue 38's confirmation
//                                          left with that machine: docs/drift.md)
//   [--margin M --consistency C --tolerance T]  a rule other than the default (tuning only)
//   [--dynamic-share S]  the default's share of the dynamic kind (FitOptions::dynamic_share;
//                        0: the mlr choice alone, the rule before the second round)
// Prints one line per case (MAE um of the default, sensors, time, the better of the two, the
// default's ratio to it, the candidate chosen) and per scenario and overall: the summed MAE of
// the default against the summed better-of, the worst ratio, and the cases above 1.25.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>
#include <vector>

#include "core/random.h"
#include "drift/evaluation.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/planted_logs.h"
#include "machine/field.h"
#include "machine/instruments.h"
#include "machine/scenarios.h"
#include "machine/truth.h"

namespace {

using namespace whirl;
using namespace whirl::drift;

struct Scores {
  double mae_default = 0, mae_sensors = 0, mae_time = 0;
  std::string chosen;
  double max_tau_per_span = 0;      // default model: longest elapsed tau / trained span
  // time model: the largest step of a prediction beyond the trained time range past the
  // plateau, in the warm-up's direction [um] (<= 0: bounded by the plateau)
  double beyond_plateau_um = -1e300;
  std::string why;  // the default's choice
};

// MAE of `model` over the scored rows of the test runs (each predicted from its start).
double Mae(const DriftModel& model, const planted::Case& c) {
  double s = 0;
  long n = 0;
  for (std::size_t i = 0; i < c.test.size(); ++i) {
    const RunPrediction p = PredictRun(model, c.test[i]);
    for (int k = c.scored[i].first; k < c.scored[i].second; ++k, ++n)
      s += std::abs(p.measured_um(k) - p.predicted_um(k));
  }
  return s / static_cast<double>(n);
}

double TrainedSpan(const planted::Case& c) {
  double span = 0;
  for (const Run& r : c.train) span = std::max(span, r.time_min.back() - r.time_min.front());
  return span;
}

double g_dynamic_share = FitOptions().dynamic_share;  // --dynamic-share

Scores Score(const planted::Case& c, const ChoiceRule& rule, const std::string& error) {
  FitOptions f;
  f.threads = 1;
  f.choice = rule;
  f.dynamic_share = g_dynamic_share;
  Scores s;
  const FitReport def = FitDriftModel(c.train, error, f);
  s.mae_default = Mae(def.model, c);
  s.chosen = def.chosen.substr(8, def.chosen.find(':', 8) - 8);
  s.why = def.chosen;
  for (const auto& cs : def.candidates) {
    s.why += "\n    " + cs.name + " " + std::to_string(cs.cv_rmse_um) + ":";
    for (double v : cs.fold_rmse_um) s.why += " " + std::to_string(v);
  }
  const double span = TrainedSpan(c);
  for (double tau : def.model.elapsed_time_constants)
    s.max_tau_per_span = std::max(s.max_tau_per_span, tau / span);
  f.candidates = Candidates::kSensors;
  s.mae_sensors = Mae(FitDriftModel(c.train, error, f).model, c);
  f.candidates = Candidates::kTime;
  const DriftModel time = FitDriftModel(c.train, error, f).model;
  s.mae_time = Mae(time, c);
  const double plateau = time.linear.coefficients.sum();
  const double direction = time.linear.coefficients.tail(1)(0) >= 0 ? 1.0 : -1.0;
  for (std::size_t i = 0; i < c.test.size(); ++i) {
    const RunPrediction p = PredictRun(time, c.test[i]);
    for (int k = 0; k < c.test[i].samples(); ++k)
      if (c.test[i].time_min[static_cast<std::size_t>(k)] - c.test[i].time_min.front() > span)
        s.beyond_plateau_um =
            std::max(s.beyond_plateau_um, direction * (p.predicted_um(k) - plateau));
  }
  return s;
}

struct Tally {
  double sum_default = 0, sum_better = 0, worst = 0, worst_tau = 0, worst_plateau = -1e300;
  int cases = 0, above = 0;
  void Add(const Scores& s) {
    const double better = std::min(s.mae_sensors, s.mae_time);
    sum_default += s.mae_default;
    sum_better += better;
    worst = std::max(worst, s.mae_default / better);
    worst_tau = std::max(worst_tau, s.max_tau_per_span);
    worst_plateau = std::max(worst_plateau, s.beyond_plateau_um);
    above += s.mae_default > 1.25 * better;
    ++cases;
  }
  void Print(const std::string& name) const {
    std::printf("%-22s %3d cases  default %8.2f  better-of %8.2f  ratio %.3f  worst %.3f  above "
                "1.25: %d  tau/span <= %.3f  beyond the plateau <= %.3g um\n",
                name.c_str(), cases, sum_default, sum_better, sum_default / sum_better, worst,
                above, worst_tau, worst_plateau);
  }
};

std::vector<planted::Case> TuningCases(int seeds) {
  std::vector<planted::Case> cases;
  for (int k = 0; k < seeds; ++k) {
    Rng rng(MixSeed(38, static_cast<std::uint64_t>(k)));
    cases.push_back(planted::Warmup(rng, 1));
    cases.push_back(planted::Warmup(rng, 4));
    cases.push_back(planted::DutySensor(rng));
    cases.push_back(planted::SpindleLong(rng));
    cases.push_back(planted::SlowWarmup(rng));
    for (auto& c : planted::Production(rng, 4)) cases.push_back(std::move(c));
    for (auto& c : planted::Production(rng, 4, true)) cases.push_back(std::move(c));
  }
  return cases;
}

// The field machine's production days with the truth at the probe's position as the error
// channel (what a check ring on the chuck would read without noise), sampled every minute.
Run FieldDay(const machine::MachineTimeline& t, int day, std::uint64_t seed) {
  machine::LogOptions lo;
  lo.duty = false;
  Run r = machine::DayLog(t, day, lo, seed);
  r.error_names = {"e_um"};
  r.error_um.resize(r.samples(), 1);
  for (int k = 0; k < r.samples(); ++k)
    r.error_um(k, 0) = machine::TrueError(t, r.time_min[static_cast<std::size_t>(k)], 150).total_um();
  r.name = r.source = "day" + std::to_string(day);
  return r;
}

std::vector<planted::Case> ConfirmationCases(int seeds) {
  std::vector<planted::Case> cases;
  const machine::FieldMachineConfig field = machine::DefaultFieldMachine();
  machine::CalendarSpec spec;
  spec.past_days = 4;
  spec.test_days = 0;
  spec.laser_tests = 0;
  for (const char* name : {"constant-duty", "production", "duty-changes", "interrupted-starts",
                           "unconditioned-hall"})
    for (int k = 0; k < seeds; ++k) {
      const machine::MachineWorld w = machine::BuildMachineWorld(
          field, machine::FindMachineScenario(name), 4138, k, spec);
      std::vector<Run> days, warmups;
      for (const machine::DayPlan& d : w.timeline.days()) {
        Run r = FieldDay(w.timeline, d.day, MixSeed(w.machine_seed, 7));
        (d.role == machine::DayRole::kWarmupTest ? warmups : days).push_back(std::move(r));
      }
      for (std::size_t d = 1; d < days.size(); ++d) {
        planted::Case c;
        c.scenario = std::string("field ") + name;
        c.train = {days[d - 1]};
        c.test = {days[d]};
        c.scored = {{0, days[d].samples()}};
        cases.push_back(std::move(c));
      }
      if (std::string(name) == "production" && warmups.size() >= 2) {
        planted::Case c;  // a warm-up test trained on the other warm-up test
        c.scenario = "field warm-up test";
        c.train = {warmups[0]};
        c.test = {warmups[1]};
        c.scored = {{0, warmups[1].samples()}};
        cases.push_back(std::move(c));
      }
    }
  return cases;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2 || (std::strcmp(argv[1], "tuning") != 0 && std::strcmp(argv[1], "confirmation") != 0)) {
    std::fprintf(stderr, "usage: choice_study tuning|confirmation [--seeds N] [--margin M] "
                         "[--consistency C] [--tolerance T] [--dynamic-share S] [--quiet]\n");
    return 2;
  }
  const bool tuning = std::strcmp(argv[1], "tuning") == 0;
  int seeds = 6;
  bool quiet = false, verbose = false;
  ChoiceRule rule;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--quiet" || a == "--verbose") {
      (a == "--quiet" ? quiet : verbose) = true;
      continue;
    }
    if (i + 1 >= argc) return 2;
    const double v = std::atof(argv[++i]);
    if (a == "--seeds") seeds = static_cast<int>(v);
    else if (a == "--margin") rule.margin = v;
    else if (a == "--consistency") rule.consistency = v;
    else if (a == "--tolerance") rule.tolerance = v;
    else if (a == "--dynamic-share") g_dynamic_share = v;
    else return 2;
  }
  const std::vector<planted::Case> cases = tuning ? TuningCases(seeds) : ConfirmationCases(seeds);
  std::map<std::string, Tally> by;
  Tally all;
  if (!quiet) std::printf("scenario               default  sensors     time   better  ratio  chosen\n");
  for (const planted::Case& c : cases) {
    const Scores s = Score(c, rule, "e_um");
    by[c.scenario].Add(s);
    all.Add(s);
    if (!quiet)
      std::printf("%-22s %8.3f %8.3f %8.3f %8.3f  %.3f  %s\n", c.scenario.c_str(), s.mae_default,
                  s.mae_sensors, s.mae_time, std::min(s.mae_sensors, s.mae_time),
                  s.mae_default / std::min(s.mae_sensors, s.mae_time),
                  (verbose ? s.why : s.chosen).c_str());
  }
  for (const auto& [name, t] : by) t.Print(name);
  all.Print("all");
  return 0;
}
