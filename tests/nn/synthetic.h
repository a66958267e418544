#pragma once
// Synthetic training problems for the nn tests: smooth functions of five inputs with seeded noise.
#include <cmath>
#include <cstdint>

#include "core/process.h"
#include "core/random.h"
#include "nn/network.h"
#include "nn/trainbr.h"

namespace whirl::nn::synth {

/// A smooth 5-input, 2-output function on [-1, 1]^5 (not a network, so no size fits it exactly).
inline Eigen::Vector2d SmoothFunction(const Eigen::VectorXd& x) {
  return {std::sin(1.5 * x(0)) + 0.5 * x(1) * x(2) + 0.3 * x(3) * x(3) - 0.4 * x(4),
          0.6 * std::tanh(x(0) + x(1)) + 0.3 * std::cos(2 * x(2)) + 0.2 * x(3) * x(4)};
}

/// Standard normal by Box-Muller from the fixed-mapping Rng.
inline double Gaussian(Rng* rng) {
  const double u1 = 1.0 - rng->Uniform();  // (0, 1]
  const double u2 = rng->Uniform();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

/// Q samples of SmoothFunction on uniform inputs in [-1, 1]^5, targets plus N(0, noise^2),
/// already in the normalized space (identity target scaling).
inline TrainingData SmoothProblem(int Q, double noise, std::uint64_t seed) {
  Rng rng(seed);
  TrainingData d;
  d.inputs.resize(5, Q);
  d.targets.resize(2, Q);
  for (int q = 0; q < Q; ++q) {
    for (int i = 0; i < 5; ++i) d.inputs(i, q) = rng.Uniform(-1, 1);
    d.targets.col(q) = SmoothFunction(d.inputs.col(q));
    for (int k = 0; k < 2; ++k) d.targets(k, q) += noise * Gaussian(&rng);
  }
  d.target_scaling = MapMinMax::Identity(2);
  return d;
}

/// A process table in the paper's ranges (Li, Ma and Jiang) whose targets are a smooth
/// function of the inputs plus noise: max elongation ~ 100-200 um, settle time ~ 150-300 s.
inline ProcessTable SyntheticProcessTable(int Q, double noise, std::uint64_t seed) {
  Rng rng(seed);
  ProcessTable t;
  t.source = "synthetic";
  for (int q = 0; q < Q; ++q) {
    Eigen::VectorXd u(5);
    for (int i = 0; i < 5; ++i) u(i) = rng.Uniform(-1, 1);
    const Eigen::Vector2d f = SmoothFunction(u);
    ProcessInputs in;
    in.hardness_hrc = 62.5 + 2.5 * u(0);
    in.diameter_mm = 75 + 25 * u(1);
    in.pitch_mm = 11 + 5 * u(2);
    in.raceway_radius_mm = 6.5 + 3.5 * u(3);
    in.cutting_speed_m_min = 180 + 30 * u(4);
    Features out;
    out.max_elongation_um = 150 + 30 * (f(0) + noise * Gaussian(&rng));
    out.settle_time_s = 220 + 50 * (f(1) + noise * Gaussian(&rng));
    t.inputs.push_back(in);
    t.targets.push_back(out);
    t.line_numbers.push_back(q + 2);
  }
  return t;
}

}  // namespace whirl::nn::synth
