#pragma once
// Generated process tables for the model tests (family/, workpiece/).
#include <algorithm>
#include <array>
#include <cmath>
#include <random>

#include "core/process.h"

namespace whirl::test {

// Inputs uniform in the paper's ranges; targets a power law times exp(noise_sd N(0, 1)), or the
// smooth non-power law of `curved`.
inline ProcessTable MakeTable(int rows, double noise_sd, unsigned seed, bool curved = false) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> n01;
  const double lo[5] = {60, 50, 6, 3, 150}, span[5] = {5, 50, 10, 7, 60};
  ProcessTable t;
  t.source = "generated.csv";
  for (int q = 0; q < rows; ++q) {
    std::array<double, 5> x{};
    for (int i = 0; i < 5; ++i) x[i] = lo[i] + span[i] * u(rng);
    double e = 30 * std::pow(x[3], 1.97) * std::pow(x[4], -1.7) * std::pow(x[2], -0.99) * 1e3;
    double s = 2.0 * std::pow(x[1], 0.8) * std::pow(x[0] / 60, 3.0);
    if (curved) {
      e = 10 + 5 * std::sin(x[3]) + 0.1 * x[1];
      s = 50 + 20 * std::cos(x[2] / 3) * (x[4] / 150);
    }
    t.inputs.push_back(ProcessInputs::FromArray(x));
    t.targets.push_back(Features::FromArray(
        {e * std::exp(noise_sd * n01(rng)), s * std::exp(noise_sd * n01(rng))}));
  }
  return t;
}

// MakeTable's power law with max elongation times exp(bend ln^2(raceway radius / 6)): a real bend
// in one input (the practical-equivalence tests and tests/family/bend_probe.cpp).
inline ProcessTable MakeBentTable(int rows, double noise_sd, double bend, unsigned seed) {
  ProcessTable t = MakeTable(rows, noise_sd, seed);
  for (std::size_t q = 0; q < t.targets.size(); ++q)
    t.targets[q].max_elongation_um *=
        std::exp(bend * std::pow(std::log(t.inputs[q].raceway_radius_mm / 6), 2));
  return t;
}

// Friedman #2 (max elongation) and #3 (settle time) (Friedman, "Multivariate adaptive regression
// splines", 1991; Breiman, "Bagging predictors", 1996) on u_1..u_4 of u ~ U[0, 1]^5 (u_5 does not
// matter), the inputs MakeTable's ranges: x1 = 100 u1, x2 = 40 pi + 520 pi u2, x3 = u3,
// x4 = 1 + 10 u4, g = x2 x3 - 1 / (x2 x4); f2 = sqrt(x1^2 + g^2) + 500, f3 = 100 atan(g / x1)
// + 200, noise sd a third of each function's sd (125 and 31), as scripts/bench_peers.py's
// friedman23 family.
inline ProcessTable MakeFriedman23Table(int rows, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::normal_distribution<double> n01;
  const double lo[5] = {60, 50, 6, 3, 150}, span[5] = {5, 50, 10, 7, 60};
  const double pi = std::acos(-1.0);
  ProcessTable t;
  t.source = "friedman23.csv";
  for (int q = 0; q < rows; ++q) {
    std::array<double, 5> u{}, x{};
    for (int i = 0; i < 5; ++i) u[i] = u01(rng);
    for (int i = 0; i < 5; ++i) x[i] = lo[i] + span[i] * u[i];
    const double x1 = 100 * u[0], x2 = 40 * pi + 520 * pi * u[1], x3 = u[2], x4 = 1 + 10 * u[3];
    const double g = x2 * x3 - 1 / (x2 * x4);
    const double f2 = std::sqrt(x1 * x1 + g * g) + 500;
    const double f3 = 100 * std::atan(g / std::max(x1, 1e-9)) + 200;
    t.inputs.push_back(ProcessInputs::FromArray(x));
    t.targets.push_back(Features::FromArray({f2 + 125 * n01(rng), f3 + 31 * n01(rng)}));
  }
  return t;
}

}  // namespace whirl::test
