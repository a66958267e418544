// Restarts, hidden-size sweeps and the stopping/noise folds run through ParallelFor;
// the results must not depend on the thread count. And the cross-validated stopping rule: its
// epoch limit is the argmin of the summed held-out curve, and the model is trained with it.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "core/error.h"
#include "core/json_file.h"
#include "nn/model.h"
#include "nn/selection.h"
#include "nn/trainbr.h"
#include "synthetic.h"

namespace whirl::nn {
namespace {

TEST(ParallelNn, RestartsAreIdenticalForAnyThreadCount) {
  const ProcessTable table = synth::SyntheticProcessTable(20, 0.05, 3);
  const MapMinMax xs = MapMinMax::Fit(InputMatrix(table.inputs));
  const MapMinMax ts = MapMinMax::Fit(TargetMatrix(table.targets));
  const TrainingData data{xs.Apply(InputMatrix(table.inputs)),
                          ts.Apply(TargetMatrix(table.targets)), ts};
  TrainOptions o;
  o.epochs = 80;
  const RestartResult one = TrainBrRestarts(data, {5, 6, 2}, 11, 5, o, {}, 1);
  for (int threads : {2, 4}) {
    const RestartResult r = TrainBrRestarts(data, {5, 6, 2}, 11, 5, o, {}, threads);
    EXPECT_EQ(r.best_index, one.best_index) << threads;
    EXPECT_EQ(r.best.network.GetParameters(), one.best.network.GetParameters()) << threads;
    ASSERT_EQ(r.runs.size(), one.runs.size());
    for (std::size_t k = 0; k < r.runs.size(); ++k)
      EXPECT_EQ(r.runs[k].log_evidence, one.runs[k].log_evidence) << threads << " run " << k;
  }
}

TEST(ParallelNn, SweepIsIdenticalForAnyThreadCount) {
  const ProcessTable table = synth::SyntheticProcessTable(24, 0.05, 4);
  SweepOptions o;
  o.hidden_min = 2;
  o.hidden_max = 3;
  o.folds = 4;
  o.train.epochs = 60;
  o.threads = 1;
  const nlohmann::json one = HiddenSweep(table, o);
  for (int threads : {2, 4}) {
    o.threads = threads;
    EXPECT_EQ(nlohmann::json(HiddenSweep(table, o)).dump(), one.dump()) << threads;
  }
}

TEST(ParallelNn, DefaultModelIsIdenticalForAnyThreadCount) {
  const ProcessTable table = synth::SyntheticProcessTable(20, 0.05, 5);
  ModelTrainOptions o;
  o.restarts = 3;
  o.train.epochs = 150;
  o.threads = 1;
  const std::string one = nlohmann::json(TrainModel(table, o, "t.csv")).dump();
  for (int threads : {2, 4}) {
    o.threads = threads;
    EXPECT_EQ(nlohmann::json(TrainModel(table, o, "t.csv")).dump(), one) << threads;
  }
}

TEST(CrossValidatedStopping, EpochLimitIsTheArgminOfTheHeldOutCurveAndIsUsed) {
  const ProcessTable table = synth::SyntheticProcessTable(20, 0.05, 6);
  ModelTrainOptions o;
  o.train.epochs = 200;
  o.stopping = Stopping::kCrossValidated;
  std::vector<double> curve;
  const int e = ChooseEpochsByCrossValidation(table, o, 5, &curve);
  ASSERT_EQ(curve.size(), 200u);
  EXPECT_GE(e, 1);
  EXPECT_LE(e, 200);
  EXPECT_EQ(e, std::min_element(curve.begin(), curve.end()) - curve.begin() + 1);
  for (double c : curve) EXPECT_GE(c, curve[e - 1]);
  const Model m = TrainModel(table, o, "t.csv");
  EXPECT_EQ(m.train_options.epochs, e);
  EXPECT_LE(m.training_summary.epochs, e);
  EXPECT_NE(m.stopping.find("cross-validation"), std::string::npos) << m.stopping;
  o.stopping = Stopping::kTrainbrMatlab;
  const Model matlab = TrainModel(table, o, "t.csv");
  EXPECT_EQ(matlab.train_options.epochs, 200);
  EXPECT_NE(matlab.stopping.find("MATLAB"), std::string::npos) << matlab.stopping;
  EXPECT_THROW(ChooseEpochsByCrossValidation(table, o, 1), InputError);
  EXPECT_THROW(ChooseEpochsByCrossValidation(table, o, 21), InputError);
}

}  // namespace
}  // namespace whirl::nn

namespace whirl::nn {
namespace {

TEST(HiddenAuto, ChoosesTheCandidateWithTheLowestCrossValidationError) {
  const ProcessTable table = synth::SyntheticProcessTable(24, 0.05, 7);
  ModelTrainOptions o;
  o.train.epochs = 100;
  o.hidden_candidates = {2, 5};
  const Model m = TrainModel(table, o, "t.csv");
  SweepOptions s;
  s.folds = 5;
  s.train = o.train;
  s.hidden_min = 2;
  s.hidden_max = 5;
  const std::vector<SweepRow> rows = HiddenSweep(table, s);
  const int expect = rows[0].cv_rms_normalized <= rows[3].cv_rms_normalized ? 2 : 5;
  EXPECT_EQ(m.network.layer_sizes, (std::vector<int>{5, expect, 2}));
  EXPECT_NE(m.hidden_selection.find("chosen by 5-fold"), std::string::npos) << m.hidden_selection;
  // The fixed-size model of the chosen size is the same network.
  o.hidden_candidates.clear();
  o.hidden_sizes = {expect};
  EXPECT_EQ(TrainModel(table, o, "t.csv").network.GetParameters(), m.network.GetParameters());
}

}  // namespace
}  // namespace whirl::nn

namespace whirl::nn {
namespace {

// The default training: the size of the highest log evidence among the candidates,
// each fit with brnn's rule; the chosen model is the fixed-size fit of that size (before the
// noise calibration, which uses the same folds), and any thread count gives the same file.
TEST(HiddenByEvidence, ChoosesTheHighestEvidenceAndIsIdenticalForAnyThreadCount) {
  const ProcessTable table = synth::SyntheticProcessTable(24, 0.05, 9);
  ModelTrainOptions o = DefaultTrainingOptions();
  ASSERT_TRUE(o.hidden_by_evidence);
  EXPECT_EQ(o.train.change, kBrnnChange);
  o.threads = 1;
  const Model one = TrainModel(table, o, "t.csv");
  std::vector<Model> fits;
  std::size_t best = 0;
  for (int h : o.hidden_candidates) {
    ModelTrainOptions fixed = o;
    fixed.hidden_candidates.clear();
    fixed.hidden_sizes = h == 0 ? std::vector<int>{} : std::vector<int>{h};  // 0: linear
    fits.push_back(TrainModel(table, fixed, "t.csv"));
    const TrainSummary& s = fits.back().training_summary;
    EXPECT_NE(s.termination, TrainTermination::kMaxEpochs) << s.BriefReport();
    if (s.log_evidence > fits[best].training_summary.log_evidence) best = fits.size() - 1;
  }
  EXPECT_EQ(fits[best].network.GetParameters(), one.network.GetParameters());
  EXPECT_EQ(fits[best].output_noise_variance, one.output_noise_variance);
  const int h = o.hidden_candidates[best];
  const std::vector<int> sizes = h == 0 ? std::vector<int>{5, 2} : std::vector<int>{5, h, 2};
  EXPECT_EQ(one.network.layer_sizes, sizes);
  EXPECT_NE(one.hidden_selection.find("highest log evidence"), std::string::npos)
      << one.hidden_selection;
  const nlohmann::json reference = one;
  for (int threads : {2, 4}) {
    o.threads = threads;
    EXPECT_EQ(nlohmann::json(TrainModel(table, o, "t.csv")).dump(), reference.dump()) << threads;
  }
}

}  // namespace
}  // namespace whirl::nn
