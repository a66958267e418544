#pragma once
// Synthetic runs for the drift tests: sensor groups that share a latent temperature, an error
// driven by chosen groups (documented here, generated from a seed).
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "drift/regression.h"
#include "drift/run_file.h"

namespace whirl::drift::synth {

/// Latent rise g of group k at time t [min]: three shapes that are far from collinear
/// (a fast first-order rise, a slow ramp with a cool-down, an oscillation).
inline double Latent(int k, double t) {
  switch (k % 3) {
    case 0:
      return 8.0 * (1.0 - std::exp(-t / 20.0));
    case 1:
      return t < 150 ? t / 25.0 : 6.0 - (t - 150) / 30.0;
    default:
      return 3.0 * std::sin(t / 25.0) + 0.01 * t;
  }
}

/// A run of `samples` samples every minute: `groups` groups of `per_group` sensors, sensor j of
/// group k = 20 + (0.6 + 0.4 j) Latent(k) + N(0, noise); error = sum_k weights[k] Latent(k) +
/// N(0, error_noise). Sensors are ordered group by group (k0s0, k0s1, ..., k1s0, ...).
inline Run PlantedRun(unsigned seed, int groups, int per_group, const std::vector<double>& weights,
                      int samples = 300, double noise = 0.02, double error_noise = 0.1) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n01(0.0, 1.0);
  Run r;
  r.name = r.source = "planted_" + std::to_string(seed);
  for (int k = 0; k < groups; ++k)
    for (int j = 0; j < per_group; ++j)
      r.sensor_names.push_back("g" + std::to_string(k) + "s" + std::to_string(j) + "_C");
  r.error_names = {"e_um"};
  r.temperature_C.resize(samples, groups * per_group);
  r.error_um.resize(samples, 1);
  r.other.resize(samples, 0);
  for (int q = 0; q < samples; ++q) {
    const double t = q;
    r.time_min.push_back(t);
    r.line_numbers.push_back(q + 2);
    double e = 0;
    for (int k = 0; k < groups; ++k) {
      for (int j = 0; j < per_group; ++j)
        r.temperature_C(q, k * per_group + j) =
            20.0 + (0.6 + 0.4 * j) * Latent(k, t) + noise * n01(rng);
      e += weights[static_cast<std::size_t>(k)] * Latent(k, t);
    }
    r.error_um(q, 0) = e + error_noise * n01(rng);
  }
  return r;
}

/// 400 noise-free samples of three one-sensor groups whose error is 3 L_40(dT_a) - dT_b: sensors
/// g0s0_C (a) and g2s0_C (b), the lag of a with tau = 40 min (drift/regression.h FirstOrderLag).
inline Run LaggedRun() {
  Run run = PlantedRun(9, 3, 1, {0.0, 0.0, 0.0}, 400, 0.0, 0.0);
  const Eigen::MatrixXd d = run.Rises();
  run.error_um.col(0) = 3.0 * FirstOrderLag(d.col(0), run.time_min, 40.0) - d.col(2);
  return run;
}

}  // namespace whirl::drift::synth
