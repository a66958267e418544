#pragma once
// Planted thermal-drift logs for the choice between the sensor model and the elapsed-time models
// (drift/fit.h ChooseCandidate): one heat source (a spindle) with a duty u(t) in [0, 1] drawn per
// scenario, a slow ambient, and first-order responses to them. Sensor i reads
//   T_i = 20 + g_i L_{tau_i}(u) + c_i amb(t) + N(0, noise_k),
// the error is
//   e = sum_j a_j L_{te_j}(u) + d amb(t) + N(0, noise_um),
// L_tau the first-order lag of u (drift/regression.h FirstOrderLag, exact for a held input),
// carried across runs and decaying while the machine is off. Elapsed time is a good proxy where u
// is held from the run's start (a warm-up), the sensors where a sensor's lag matches the error's.
// The scenarios mimic what the choice must get right (issue 38):
//   warmup1, warmup4  warm-up runs at one duty (time is nearly the truth), trained on 1 or 4 runs
//   duty_sensor       a random duty that one sensor follows with the error's own lag (sensors)
//   spindle_long      a 78-h spindle log of speed steps, first half trained (sensors)
//   slow_warmup       one duty held for the whole log, the error's time constant 2-4 x the
//                     trained span (time, bounded)
//   production        days of one shift (set-ups, cuts, breaks), refitted each day on the
//                     previous one (both explain part)
//   production_slow   the same with a slow structure no sensor sees dominating the error
// Used by tests/drift/choice_study.cpp (the tuning set of the choice rule) and the planted-log
// tests. Deterministic per seed on every standard library (core/random.h's Rng).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/random.h"
#include "drift/run_file.h"

namespace whirl::drift::planted {

/// A held duty level from `start_min` on.
struct DutyStep {
  double start_min = 0;
  double level = 0;
};

struct Machine {
  std::vector<double> sensor_tau_min, sensor_gain_k, sensor_ambient;  ///< per sensor
  std::vector<double> error_tau_min, error_gain_um;                   ///< per error term
  double error_ambient_um_per_k = 0;
  double ambient_k_per_h = 0;      ///< slow ambient ramp
  double ambient_swing_k = 0;      ///< plus a 24-h sine of this amplitude
  double noise_k = 0.02, noise_um = 0.2;
};

/// Lag states of every sensor and error term (carried across runs; 0 = cold).
struct State {
  std::vector<double> sensor, error;
  double clock_min = 0;  ///< absolute time (the ambient's clock)
};

inline State Cold(const Machine& m) {
  return {std::vector<double>(m.sensor_tau_min.size(), 0.0),
          std::vector<double>(m.error_tau_min.size(), 0.0), 0.0};
}

/// The machine switched off for `minutes`: every lag decays towards 0.
inline void Off(const Machine& m, double minutes, State* s) {
  for (std::size_t i = 0; i < s->sensor.size(); ++i)
    s->sensor[i] *= std::exp(-minutes / m.sensor_tau_min[i]);
  for (std::size_t j = 0; j < s->error.size(); ++j)
    s->error[j] *= std::exp(-minutes / m.error_tau_min[j]);
  s->clock_min += minutes;
}

inline double Ambient(const Machine& m, double clock_min) {
  return m.ambient_k_per_h * clock_min / 60 +
         m.ambient_swing_k * std::sin(2 * M_PI * clock_min / 1440.0);
}

/// One run of `duration_min` sampled every `step_min` with the duty `steps` (times from the run's
/// start), from state *s (updated). Columns time_min, t<i>_C, e_um.
inline Run Simulate(const Machine& m, const std::vector<DutyStep>& steps, double duration_min,
                    double step_min, Rng& rng, State* s, const std::string& name) {
  Run r;
  r.name = r.source = name;
  const std::size_t ns = m.sensor_tau_min.size();
  for (std::size_t i = 0; i < ns; ++i) r.sensor_names.push_back("t" + std::to_string(i + 1) + "_C");
  r.error_names = {"e_um"};
  const int n = static_cast<int>(std::floor(duration_min / step_min)) + 1;
  r.temperature_C.resize(n, static_cast<Eigen::Index>(ns));
  r.error_um.resize(n, 1);
  r.other.resize(n, 0);
  std::size_t at = 0;
  for (int k = 0; k < n; ++k) {
    const double t = k * step_min;
    if (k > 0) {  // advance the lags over (t - step, t] with the duty held from the step's start
      while (at + 1 < steps.size() && steps[at + 1].start_min <= t - step_min) ++at;
      const double u = steps.empty() ? 0.0 : steps[at].level;
      for (std::size_t i = 0; i < ns; ++i)
        s->sensor[i] += (1 - std::exp(-step_min / m.sensor_tau_min[i])) * (u - s->sensor[i]);
      for (std::size_t j = 0; j < s->error.size(); ++j)
        s->error[j] += (1 - std::exp(-step_min / m.error_tau_min[j])) * (u - s->error[j]);
      s->clock_min += step_min;
    }
    const double amb = Ambient(m, s->clock_min);
    r.time_min.push_back(t);
    r.line_numbers.push_back(k + 2);
    for (std::size_t i = 0; i < ns; ++i)
      r.temperature_C(k, static_cast<Eigen::Index>(i)) = 20 + m.sensor_gain_k[i] * s->sensor[i] +
                                                        m.sensor_ambient[i] * amb +
                                                        m.noise_k * rng.Normal();
    double e = m.error_ambient_um_per_k * amb + m.noise_um * rng.Normal();
    for (std::size_t j = 0; j < s->error.size(); ++j) e += m.error_gain_um[j] * s->error[j];
    r.error_um(k, 0) = e;
  }
  return r;
}

/// Random duty: held levels of U(lo_min, hi_min) minutes each, a level of 0 with probability
/// `p_off`, else U(level_lo, 1).
inline std::vector<DutyStep> RandomDuty(Rng& rng, double duration_min, double lo_min,
                                        double hi_min, double p_off, double level_lo) {
  std::vector<DutyStep> d;
  for (double t = 0; t < duration_min; t += rng.Uniform(lo_min, hi_min))
    d.push_back({t, rng.Uniform() < p_off ? 0.0 : rng.Uniform(level_lo, 1.0)});
  return d;
}

/// A case of the study: training runs, runs to predict from their start, and the scored rows of
/// each (begin, end) (all rows of a separate test run; the rows after the training part of a log
/// cut at a split point).
struct Case {
  std::string scenario;
  std::vector<Run> train;
  std::vector<Run> test;
  std::vector<std::pair<int, int>> scored;
};

/// Sensors with lags spread over [lo, hi] min (log-spaced), gains U(2, 8) K, small ambient parts.
inline void SpreadSensors(Rng& rng, int count, double lo, double hi, Machine* m) {
  for (int i = 0; i < count; ++i) {
    const double f = count > 1 ? static_cast<double>(i) / (count - 1) : 0.5;
    m->sensor_tau_min.push_back(lo * std::pow(hi / lo, f) * rng.Uniform(0.8, 1.25));
    m->sensor_gain_k.push_back(rng.Uniform(2, 8));
    m->sensor_ambient.push_back(rng.Uniform(0.5, 1.0));
  }
}

inline Case Warmup(Rng& rng, int training_runs) {
  Machine m;
  SpreadSensors(rng, 4, 5, 60, &m);
  m.error_tau_min = {rng.Uniform(40, 120)};
  m.error_gain_um = {rng.Uniform(8, 20) * (rng.Uniform() < 0.5 ? -1 : 1)};
  m.ambient_k_per_h = rng.Uniform(-0.05, 0.05);
  m.error_ambient_um_per_k = rng.Uniform(-1, 1);
  const double level = rng.Uniform(0.6, 1.0);
  Case c;
  c.scenario = training_runs == 1 ? "warmup1" : "warmup4";
  for (int k = 0; k < training_runs + 2; ++k) {
    State s = Cold(m);
    s.clock_min = k * 1440.0;
    const double duration = rng.Uniform(180, 300);
    Run r = Simulate(m, {{0, level * rng.Uniform(0.9, 1.1)}}, duration, 1.0, rng, &s,
                     "warmup_" + std::to_string(k + 1));
    if (k < training_runs) {
      c.train.push_back(std::move(r));
    } else {
      c.scored.emplace_back(0, r.samples());
      c.test.push_back(std::move(r));
    }
  }
  return c;
}

inline Case DutySensor(Rng& rng) {
  Machine m;
  SpreadSensors(rng, 4, 5, 120, &m);
  const std::size_t k = std::min<std::size_t>(3, static_cast<std::size_t>(4 * rng.Uniform()));
  m.error_tau_min = {m.sensor_tau_min[k]};
  m.error_gain_um = {rng.Uniform(2, 4) * m.sensor_gain_k[k]};
  Case c;
  c.scenario = "duty_sensor";
  State s = Cold(m);
  for (int run = 0; run < 2; ++run) {
    const double duration = rng.Uniform(300, 480);
    Run r = Simulate(m, RandomDuty(rng, duration, 30, 90, 0.3, 0.2), duration, 1.0, rng, &s,
                     "duty_" + std::to_string(run + 1));
    Off(m, 600, &s);
    if (run == 0) {
      c.train.push_back(std::move(r));
    } else {
      c.scored.emplace_back(0, r.samples());
      c.test.push_back(std::move(r));
    }
  }
  return c;
}

/// One log cut at `split` of its rows: the prefix trains, the whole log is predicted from its
/// start and the rows after the prefix are scored.
inline void SplitLog(Run log, double split, Case* c) {
  const int a = static_cast<int>(split * log.samples());
  c->train.push_back(log.Slice(0, a, log.name + "_train"));
  c->scored.emplace_back(a, log.samples());
  c->test.push_back(std::move(log));
}

inline Case SpindleLong(Rng& rng) {
  Machine m;
  SpreadSensors(rng, 5, 10, 240, &m);
  // The error follows two of the sensors' dynamics closely (the sensors explain it), plus a
  // slow ambient part.
  m.error_tau_min = {m.sensor_tau_min[1] * rng.Uniform(0.9, 1.1),
                     m.sensor_tau_min[3] * rng.Uniform(0.9, 1.1)};
  m.error_gain_um = {rng.Uniform(5, 15), rng.Uniform(-10, 10)};
  m.ambient_swing_k = rng.Uniform(0.5, 2.0);
  m.error_ambient_um_per_k = rng.Uniform(-2, 2);
  std::vector<DutyStep> duty{{0, rng.Uniform(0.5, 1.0)}};
  for (double t = 240; t < 78 * 60; t += rng.Uniform(120, 480))
    duty.push_back({t, rng.Uniform() < 0.25 ? 0.0 : rng.Uniform(0.3, 1.0)});
  State s = Cold(m);
  Case c;
  c.scenario = "spindle_long";
  SplitLog(Simulate(m, duty, 78 * 60, 2.0, rng, &s, "spindle"), 0.5, &c);
  return c;
}

inline Case SlowWarmup(Rng& rng) {
  Machine m;
  SpreadSensors(rng, 4, 5, 20, &m);
  const double duration = rng.Uniform(480, 720), split = 0.4;
  m.error_tau_min = {rng.Uniform(2, 4) * split * duration};
  m.error_gain_um = {rng.Uniform(15, 40)};
  State s = Cold(m);
  Case c;
  c.scenario = "slow_warmup";
  SplitLog(Simulate(m, {{0, rng.Uniform(0.6, 1.0)}}, duration, 1.0, rng, &s, "slow"), split, &c);
  return c;
}

/// Days of one shift: power-on, set-ups at 0.1, cuts at U(0.7, 1.0) for 30-60 min, breaks of 0
/// at 3 h (15 min) and 6 h (30 min); 16 h off between days.
inline std::vector<DutyStep> ShiftDuty(Rng& rng, double shift_min) {
  std::vector<DutyStep> d;
  bool first_break = false, second_break = false;
  for (double t = 0; t < shift_min;) {
    d.push_back({t, 0.1});
    t += rng.Uniform(20, 40);
    d.push_back({t, rng.Uniform(0.7, 1.0)});
    t += rng.Uniform(30, 60);
    if (!first_break && t >= 180) d.push_back({t, 0.0}), t += 15, first_break = true;
    if (!second_break && t >= 360) d.push_back({t, 0.0}), t += 30, second_break = true;
  }
  return d;
}

/// Production days: a fast part the sensors follow and a slow structural part no sensor sees
/// (it rises from each morning like a warm-up); refitted each day on the previous day.
/// `slow`: the sensors sit on fast surfaces (lags 5-20 min) and the slow part dominates (a
/// structure no sensor sees that warms from each morning: elapsed time since power-on helps).
inline std::vector<Case> Production(Rng& rng, int days, bool slow = false) {
  Machine m;
  SpreadSensors(rng, 4, 5, slow ? 20 : 60, &m);
  m.error_tau_min = {m.sensor_tau_min[1] * rng.Uniform(0.8, 1.25),
                     slow ? rng.Uniform(150, 400) : rng.Uniform(120, 300)};
  m.error_gain_um = {rng.Uniform(4, 10) * (slow ? 0.5 : 1.0),
                     slow ? rng.Uniform(8, 20) : rng.Uniform(5, 15)};
  m.ambient_swing_k = rng.Uniform(0.3, 1.5);
  m.error_ambient_um_per_k = rng.Uniform(-2, 2);
  State s = Cold(m);
  std::vector<Run> logs;
  for (int d = 0; d < days; ++d) {
    const double shift = rng.Uniform(450, 510);
    logs.push_back(Simulate(m, ShiftDuty(rng, shift), shift, 1.0, rng, &s,
                            "day_" + std::to_string(d + 1)));
    Off(m, 1440 - shift, &s);
  }
  std::vector<Case> cases;
  for (int d = 1; d < days; ++d) {
    Case c;
    c.scenario = slow ? "production_slow" : "production";
    c.train.push_back(logs[static_cast<std::size_t>(d - 1)]);
    c.scored.emplace_back(0, logs[static_cast<std::size_t>(d)].samples());
    c.test.push_back(logs[static_cast<std::size_t>(d)]);
    cases.push_back(std::move(c));
  }
  return cases;
}

}  // namespace whirl::drift::planted
