// fit hot paths: the full arctan fit of one curve (the per-curve cost of 'whirl fit' and of the
// shape calibration) and the three-model comparison.
#include <benchmark/benchmark.h>

#include <random>

#include "fit/arctan_curve.h"
#include "fit/curve_fit.h"

namespace {

using namespace whirl;
using namespace whirl::fit;

// A noisy arctan curve sampled at 1 s over 2 t_s (the window the simulated fits use).
ElongationCurve NoisyCurve(std::uint64_t seed, int samples) {
  std::mt19937 rng(static_cast<std::mt19937::result_type>(seed));
  std::normal_distribution<double> noise(0.0, 0.25);
  const ArctanCurve c{30.0, 0.5 * samples, 5.63};
  ElongationCurve curve;
  for (int i = 0; i < samples; ++i) {
    curve.time_s.push_back(i);
    curve.elongation_um.push_back(c.ElongationUm(i) + noise(rng));
  }
  return curve;
}

void BM_ArctanFit(benchmark::State& state) {
  const ElongationCurve curve = NoisyCurve(1, static_cast<int>(state.range(0)));
  double iterations = 0, runs = 0;
  for (auto _ : state) {
    const CurveFit f = FitCurveModel(curve, CurveModel::kArctan);
    benchmark::DoNotOptimize(f.parameters.data());
    iterations += f.summary.iterations;
    runs += 1;
  }
  state.counters["lm_iterations"] = iterations / runs;
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_ArctanFit)->Arg(500)->Arg(2000)->Unit(benchmark::kMillisecond);

void BM_AllThreeModels(benchmark::State& state) {
  const ElongationCurve curve = NoisyCurve(2, 500);
  for (auto _ : state) benchmark::DoNotOptimize(FitAllModels(curve).size());
}
BENCHMARK(BM_AllThreeModels)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
