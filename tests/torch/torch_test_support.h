#pragma once
// Shared by the LibTorch tests and the model-making helper of the CLI smoke tests: a synthetic,
// smooth process table (no simulator involved) and a small trainbr model trained on it.
#include <cmath>
#include <cstdint>

#include "core/process.h"
#include "core/random.h"
#include "nn/model.h"
#include "nn/network.h"

namespace whirl::test {

/// Q samples drawn uniformly in the paper's ranges (Li, Ma and Jiang) with smooth,
/// mildly nonlinear targets of a plausible size (tens of um, a few hundred s)
/// plus seeded measurement noise.
inline ProcessTable SyntheticTable(int samples, std::uint64_t seed) {
  Rng rng(seed);
  ProcessTable table;
  table.source = "synthetic table (seed " + std::to_string(seed) + ")";
  for (int q = 0; q < samples; ++q) {
    ProcessInputs in;
    in.hardness_hrc = rng.Uniform(60, 65);
    in.diameter_mm = rng.Uniform(50, 100);
    in.pitch_mm = rng.Uniform(6, 16);
    in.raceway_radius_mm = rng.Uniform(3, 10);
    in.cutting_speed_m_min = rng.Uniform(150, 210);
    Features out;
    out.max_elongation_um = 30 + 0.5 * (in.diameter_mm - 50) - 1.5 * (in.hardness_hrc - 60) +
                            0.06 * std::pow(in.pitch_mm - 6, 2) + 0.8 * in.raceway_radius_mm -
                            0.05 * (in.cutting_speed_m_min - 150);
    out.settle_time_s = 150 + 1.5 * (in.diameter_mm - 50) + 3 * std::sqrt(in.pitch_mm) -
                        0.3 * (in.cutting_speed_m_min - 150) +
                        8 * std::tanh((in.raceway_radius_mm - 6) / 2);
    // Measurement noise (uniform, +-0.5 um and +-3 s) so trainbr has a finite noise level.
    out.max_elongation_um += rng.Uniform(-0.5, 0.5);
    out.settle_time_s += rng.Uniform(-3, 3);
    table.inputs.push_back(in);
    table.targets.push_back(out);
    table.line_numbers.push_back(q + 2);
  }
  return table;
}

/// A 5-6-2 trainbr model on SyntheticTable(20, 7): the paper's sample count.
inline nn::Model SmallTrainedModel() {
  nn::ModelTrainOptions options;
  options.seed = 3;
  options.restarts = 1;
  options.train.epochs = 300;
  options.stopping = nn::Stopping::kTrainbrMatlab;  // the cross-check is against MATLAB trainbr
  return nn::TrainModel(SyntheticTable(20, 7), options, "synthetic table (seed 7)");
}

}  // namespace whirl::test
