// Speed targets of the simulator: the whole reference screw (5100 mm of thread,
// ~2.1 h of cutting) well under one second; the 500-row table in under a minute on 2 cores.
#include <benchmark/benchmark.h>

#include "sim/dataset.h"
#include "sim/simulator.h"

namespace {

void BM_WholeReferenceScrew(benchmark::State& state) {
  const whirl::screw::Screw screw = whirl::screw::ReferenceScrew();
  whirl::sim::SimOptions options;  // duration_s = 0: the whole thread
  for (auto _ : state) benchmark::DoNotOptimize(whirl::sim::Simulate(screw, options));
  state.SetLabel("whole 5100 mm thread, 2 mm cells, 1 s steps");
}
BENCHMARK(BM_WholeReferenceScrew)->Unit(benchmark::kMillisecond)->Iterations(3);

void BM_Table500Rows(benchmark::State& state) {
  whirl::sim::DatasetOptions options;
  options.count = 500;
  options.seed = 3;
  options.threads = 2;
  for (auto _ : state) benchmark::DoNotOptimize(whirl::sim::GenerateDataset(options));
  state.SetLabel("500 rows x 1800 s, 2 threads (target < 60 s)");
}
BENCHMARK(BM_Table500Rows)->Unit(benchmark::kSecond)->Iterations(1)->UseRealTime();

}  // namespace
BENCHMARK_MAIN();
