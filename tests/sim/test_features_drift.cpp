// Settle times that survive drift. The features of a recorded curve (sensor
// noise 0.25 um, ambient drift up to 1 K/h, short and whole-thread records) must match those of
// the SAME screw and workpiece simulated without noise and drift.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/random.h"
#include "sim/dataset.h"
#include "fit/features.h"
#include "sim/simulator.h"

namespace whirl::sim {
namespace {

// Disturbances whose ambient drift is exactly `drift_k_per_h` (the simulator draws it as
// std * N(0,1), the third normal of the seed's stream: sim/simulator.h).
DisturbanceOptions WithDrift(std::uint64_t seed, double drift_k_per_h) {
  DisturbanceOptions d;
  d.enabled = true;
  d.seed = seed;
  Rng rng(seed);
  rng.Normal();
  rng.Normal();
  d.ambient_drift_std_k_per_h = drift_k_per_h / rng.Normal();
  return d;
}

DisturbanceOptions WorkpieceOnly(DisturbanceOptions d) {
  d.ambient_drift = false;
  d.measurement_noise = false;
  return d;
}

// `whirl simulate`'s defaults: the whole thread, drift std 0.2 K/h. The reference screw at seeds
// 1-20 within 10 % of its undisturbed settle time (before: 2373-4883 s at seeds 1-5 against 295 s).
TEST(FeaturesDrift, ReferenceScrewWholeThreadSeeds1To20) {
  const screw::Screw screw = screw::ReferenceScrew();
  const SimOptions sim;
  const Features undisturbed = Simulate(screw, sim, DisturbanceOptions{}).features;
  EXPECT_NEAR(undisturbed.settle_time_s, 295, 0.1 * 295);  // the old 2 % criterion's value
  double worst = 0;
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    DisturbanceOptions d;
    d.enabled = true;
    d.seed = seed;
    const SimulationResult r = Simulate(screw, sim, d);
    const double e = r.features.settle_time_s / undisturbed.settle_time_s - 1;
    worst = std::max(worst, std::abs(e));
    EXPECT_LT(std::abs(e), 0.10) << "seed " << seed << ", drift "
                                 << r.disturbances.ambient_drift_k_per_h
                                 << " K/h: " << fit::AnalyzeSettle(r.curve).message;
  }
  std::printf(
      "[ figures  ] reference screw, whole thread, seeds 1-20: undisturbed t_s %.0f s, "
      "worst settle-time deviation %.1f %%\n",
      undisturbed.settle_time_s, 100 * worst);
}

// Property over screws inside and beyond the training ranges (diameter 32-125 mm, lead 5-20 mm,
// 120-250 m/min: plateaus from a few um to over 20 um, settle times from about 1 to 18 min),
// alternately 1800 s (the tables' window) and whole-thread records, drift uniform in +-1 K/h.
TEST(FeaturesDrift, DisturbedCurvesGiveTheUndriftedFeatures) {
  constexpr int kCases = 24;
  const std::array<InputRange, ProcessInputs::kCount> ranges = {
      {{55, 66}, {32, 125}, {5, 20}, {2.5, 10}, {120, 250}}};
  const auto points = DesignPoints(kCases, 99, ranges);
  Rng rng(5);
  SimOptions sim;
  sim.cell_size_mm = 4.0;  // features move < 0.5 % (test_sim.cpp); twice as fast
  std::vector<double> settle_err, max_err, settle, plateau;
  double max_drift = 0;
  for (int c = 0; c < kCases; ++c) {
    screw::Screw screw = screw::ReferenceScrew();
    screw.process = points[c];
    sim.duration_s = c % 2 == 0 ? 1800.0 : 0.0;
    const DisturbanceOptions d = WithDrift(100 + c, 1.0 * (2 * rng.Uniform() - 1));
    const SimulationResult r = Simulate(screw, sim, d);
    const SimulationResult ref = Simulate(screw, sim, WorkpieceOnly(d));
    const fit::SettleAnalysis a = fit::AnalyzeSettle(r.curve), b = fit::AnalyzeSettle(ref.curve);
    const double e_s = std::abs(a.features.settle_time_s / b.features.settle_time_s - 1);
    const double e_m = std::abs(a.features.max_elongation_um / b.features.max_elongation_um - 1);
    settle_err.push_back(e_s);
    max_err.push_back(e_m);
    settle.push_back(b.features.settle_time_s);
    plateau.push_back(b.features.max_elongation_um);
    max_drift = std::max(max_drift, std::abs(r.disturbances.ambient_drift_k_per_h));
    EXPECT_LT(e_s, 0.10) << "case " << c << ", drift " << r.disturbances.ambient_drift_k_per_h
                         << " K/h:\n  disturbed: " << a.message << "\n  reference: " << b.message;
    EXPECT_LT(e_m, 0.04) << "case " << c << ": " << a.message << " vs " << b.message;
    EXPECT_TRUE(b.settled_before_tail) << b.message;
  }
  // The cases span what the property claims.
  EXPECT_LT(*std::min_element(plateau.begin(), plateau.end()), 5.0);
  EXPECT_GT(*std::max_element(plateau.begin(), plateau.end()), 20.0);
  EXPECT_LT(*std::min_element(settle.begin(), settle.end()), 120.0);
  EXPECT_GT(*std::max_element(settle.begin(), settle.end()), 800.0);
  EXPECT_GT(max_drift, 0.8);
  std::sort(settle_err.begin(), settle_err.end());
  std::sort(max_err.begin(), max_err.end());
  std::printf(
      "[ figures  ] %d cases, drift up to %.2f K/h: settle time |rel. error| median %.1f "
      "%%, worst %.1f %%; max elongation median %.2f %%, worst %.2f %%\n",
      kCases, max_drift, 100 * settle_err[kCases / 2], 100 * settle_err.back(),
      100 * max_err[kCases / 2], 100 * max_err.back());
}

}  // namespace
}  // namespace whirl::sim
