// The family library's fits (src/product/family, src/product/gp) on the simulator's tables, beside one trainbr fit
// and whirl's current default network fit in the same run, all on one thread:
//   BM_FamilyDefault/rows:R/loo:L  ChooseFamily with the default candidates (the
//                              cross-validated choice, then the chosen candidates' fits and
//                              calibration); the speed target of the default is 2.5 ms CPU for
//                              20 rows, both outputs;
//   BM_WorkpieceDefault/rows:R  workpiece::TrainWorkpieceModel with its defaults: what `whirl
//                              train` with no model options fits (the family choice above, plus
//                              the model's domain). The speed targets (issue 40): at most R
//                              brnn's time for both outputs, taken as 20 ms at 20 rows, 45 ms at
//                              100 rows and 1 s at 2,000 rows (brnn is not packaged for Debian);
//   BM_WorkpieceGenerated/F/rows:R  the same on a generated table of family F of
//                              scripts/bench_peers.py (friedman23, additive, interacting,
//                              powerlaw_noisy: the families whose `whirl train` took longer than
//                              the speed targets), seed 1001, R = 20 or 100 rows: committed in
//                              tests/bench/data/F_R.csv, written by scripts/bench_tables.py;
//   BM_FamilyCandidate/rows:R/candidate:C   FitCandidate of DefaultCandidates()[C] (with its
//                              calibration; no choice);
//   BM_TrainbrSingleFit/rows:R one nn::TrainModel of 5-6-2 with R brnn's stopping rule, no size
//                              choice, no noise folds (the unit of docs/network.md's figures);
//   BM_NetworkDefault/rows:R   nn::DefaultTrainingOptions() (size by evidence + 5 noise folds).
// Tables: datasets/whirling_train.csv (20 rows); the first 100 (or all 500) rows of
// datasets/whirling_500.csv (the simulator); beyond 500 rows a generated bent power law
// (tests/support/power_law_table.h MakeBentTable: 2 % noise, bend 0.5), as the simulator takes
// about 50 ms per row to generate.
#include <benchmark/benchmark.h>

#include "core/process.h"
#include "family/family.h"
#include "nn/model.h"
#include "support/power_law_table.h"
#include "workpiece/model.h"

namespace {

whirl::ProcessTable Table(int rows) {
  if (rows > 500) return whirl::test::MakeBentTable(rows, 0.02, 0.5, 1);
  const std::string dir = std::string(WHIRL_SOURCE_DIR) + "/datasets/";
  whirl::ProcessTable t =
      whirl::ReadProcessTable(dir + (rows <= 20 ? "whirling_train.csv" : "whirling_500.csv"), true);
  t.inputs.resize(static_cast<std::size_t>(rows));
  t.targets.resize(static_cast<std::size_t>(rows));
  return t;
}

// Argument loo: ChoiceOptions::closed_form_loo (0: K-fold refits of each candidate's full fit;
// 1: closed-form leave-one-out, then the chosen candidates' K-fold calibration).
void BM_FamilyDefault(benchmark::State& state) {
  const whirl::ProcessTable table = Table(static_cast<int>(state.range(0)));
  whirl::family::ChoiceOptions o;
  o.fit.threads = 1;
  o.closed_form_loo = state.range(1) == 1;
  for (auto _ : state) {
    const whirl::family::Choice c = whirl::family::ChooseFamily(table, o);
    benchmark::DoNotOptimize(c.chosen);
  }
}
BENCHMARK(BM_FamilyDefault)
    ->ArgNames({"rows", "loo"})
    ->ArgsProduct({{20, 100}, {0, 1}})
    ->Unit(benchmark::kMillisecond);

// The default `whirl train` fit of `table` on one thread, once per iteration.
void TimeDefaultFit(benchmark::State& state, const whirl::ProcessTable& table) {
  whirl::workpiece::TrainOptions o;
  o.choice.fit.threads = 1;
  for (auto _ : state) {
    const whirl::workpiece::WorkpieceModel m =
        whirl::workpiece::TrainWorkpieceModel(table, o, "bench");
    benchmark::DoNotOptimize(m.domain_max);
  }
}

void BM_WorkpieceDefault(benchmark::State& state) {
  TimeDefaultFit(state, Table(static_cast<int>(state.range(0))));
}
BENCHMARK(BM_WorkpieceDefault)
    ->ArgName("rows")
    ->Arg(20)
    ->Arg(100)
    ->Arg(500)
    ->Arg(2000)
    ->Unit(benchmark::kMillisecond);

// Arguments: family (index in kGeneratedFamilies), rows.
const char* const kGeneratedFamilies[] = {"friedman23", "additive", "interacting", "powerlaw_noisy"};

void BM_WorkpieceGenerated(benchmark::State& state) {
  const std::string family = kGeneratedFamilies[state.range(0)];
  const std::string rows = std::to_string(state.range(1));
  const whirl::ProcessTable table = whirl::ReadProcessTable(
      std::string(WHIRL_SOURCE_DIR) + "/tests/bench/data/" + family + "_" + rows + ".csv", true);
  state.SetLabel(family + "/rows:" + rows);
  TimeDefaultFit(state, table);
}
BENCHMARK(BM_WorkpieceGenerated)
    ->ArgNames({"family", "rows"})
    ->ArgsProduct({{0, 1, 2, 3}, {20, 100}})
    ->Unit(benchmark::kMillisecond);

void BM_FamilyCandidate(benchmark::State& state) {
  const whirl::ProcessTable table = Table(static_cast<int>(state.range(0)));
  const auto candidates = whirl::family::ChoiceOptions::DefaultCandidates();
  const auto& c = candidates.at(static_cast<std::size_t>(state.range(1)));
  state.SetLabel(c.Name());
  whirl::family::FitOptions o;
  for (auto _ : state) {
    const whirl::family::FamilyModel m = whirl::family::FitCandidate(table, c, o);
    benchmark::DoNotOptimize(m.gps.size());
  }
}
BENCHMARK(BM_FamilyCandidate)
    ->ArgNames({"rows", "candidate"})
    ->ArgsProduct(
        {{20, 100},
         benchmark::CreateDenseRange(
             0, static_cast<int>(whirl::family::ChoiceOptions::DefaultCandidates().size()) - 1, 1)})
    ->Unit(benchmark::kMillisecond);

// Trains the network with `o` (one thread) on the benchmark's table, 16 seeds in turn.
void TrainNetwork(benchmark::State& state, whirl::nn::ModelTrainOptions o) {
  const whirl::ProcessTable table = Table(static_cast<int>(state.range(0)));
  o.threads = 1;
  std::uint64_t i = 0;
  for (auto _ : state) {
    o.seed = 1 + (i++ % 16);
    const whirl::nn::Model m = whirl::nn::TrainModel(table, o, "bench");
    benchmark::DoNotOptimize(m.training_summary.sse);
  }
}

void BM_TrainbrSingleFit(benchmark::State& state) {
  whirl::nn::ModelTrainOptions o;
  o.train.change = whirl::nn::kBrnnChange;
  o.noise_folds = 0;
  TrainNetwork(state, o);
}
BENCHMARK(BM_TrainbrSingleFit)
    ->ArgName("rows")
    ->Arg(20)
    ->Arg(100)
    ->Arg(2000)
    ->Unit(benchmark::kMillisecond);

void BM_NetworkDefault(benchmark::State& state) {
  TrainNetwork(state, whirl::nn::DefaultTrainingOptions());
}
BENCHMARK(BM_NetworkDefault)->ArgName("rows")->Arg(20)->Arg(100)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
