// interp hot paths: breakpoints + uniform count + setting data for the reference screw's whole
// thread (7655 s of cutting on a 0.25 s check grid), and the reconstruction of the compensation.
#include <benchmark/benchmark.h>

#include "fit/arctan_curve.h"
#include "interp/sinumerik.h"

namespace {

using namespace whirl;

constexpr double kFeedMmS = 39.9738 / 60.0;  // reference screw: 39.97 mm/min (ComputeKinematics)
constexpr double kThreadMm = 5100.0;

void BM_BuildPlanReferenceScrew(benchmark::State& state) {
  const fit::ArctanCurve curve{30.0, 250.0, fit::kDefaultShapeK};
  interp::PlanOptions o;
  o.tolerance_um = static_cast<double>(state.range(0)) / 10.0;
  std::size_t points = 0, uniform = 0;
  for (auto _ : state) {
    const interp::CompensationPlan plan = interp::BuildPlan(curve, kFeedMmS, kThreadMm, o);
    points = plan.point_count;
    uniform = plan.uniform_point_count;
    benchmark::DoNotOptimize(plan.segments.data());
  }
  state.counters["points"] = static_cast<double>(points);
  state.counters["uniform_points"] = static_cast<double>(uniform);
}
BENCHMARK(BM_BuildPlanReferenceScrew)->Arg(1)->Arg(5)->Arg(20)->Unit(benchmark::kMillisecond);

void BM_AppliedCompensation(benchmark::State& state) {
  const fit::ArctanCurve curve{30.0, 250.0, fit::kDefaultShapeK};
  const interp::CompensationPlan plan = interp::BuildPlan(curve, kFeedMmS, kThreadMm, {});
  double p = 0, sum = 0;
  for (auto _ : state) {
    sum += interp::AppliedCompensationUm(plan, p);
    p = p > kThreadMm ? 0 : p + 0.37;
  }
  benchmark::DoNotOptimize(sum);
}
BENCHMARK(BM_AppliedCompensation);

}  // namespace

BENCHMARK_MAIN();
