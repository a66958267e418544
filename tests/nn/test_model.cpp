// Model file and prediction: determinism, round trip, Laplace standard deviation against an
// independent finite-difference computation, domain flags, every kind of bad model file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/random.h"
#include "nn/model.h"
#include "nn/selection.h"
#include "support/eigen_near.h"
#include "synthetic.h"
#include "support/scratch_dir.h"

namespace whirl::nn {
namespace {

namespace fs = std::filesystem;

fs::path Scratch(const std::string& name) {
  const fs::path dir = whirl::test::ScratchDir() / ("whirl_nn_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  return dir / name;
}

const Model& SharedModel() {
  static const Model m = [] {
    ModelTrainOptions o;
    o.restarts = 2;
    o.seed = 5;
    return TrainModel(synth::SyntheticProcessTable(20, 0.05, 1), o, "synthetic.csv");
  }();
  return m;
}

TEST(Model, SameSeedGivesByteIdenticalFileAndDifferentSeedDoesNot) {
  const ProcessTable table = synth::SyntheticProcessTable(20, 0.05, 2);
  ModelTrainOptions o;
  o.restarts = 3;
  o.seed = 7;
  SaveModel(Scratch("a.json"), TrainModel(table, o, "t.csv"));
  SaveModel(Scratch("b.json"), TrainModel(table, o, "t.csv"));
  o.seed = 8;
  SaveModel(Scratch("c.json"), TrainModel(table, o, "t.csv"));
  const std::string a = ReadTextFile(Scratch("a.json"));
  EXPECT_EQ(a, ReadTextFile(Scratch("b.json")));
  EXPECT_NE(a, ReadTextFile(Scratch("c.json")));
}

TEST(Model, SaveLoadRoundTripPredictsBitIdentically) {
  const Model& m = SharedModel();
  SaveModel(Scratch("rt.json"), m);
  const Model back = LoadModel(Scratch("rt.json"));
  const ProcessTable queries = synth::SyntheticProcessTable(50, 0.0, 77);
  const auto p1 = PredictBatch(m, queries.inputs);
  const auto p2 = PredictBatch(back, queries.inputs);
  for (std::size_t q = 0; q < p1.size(); ++q) {
    EXPECT_EQ(p1[q].mean.max_elongation_um, p2[q].mean.max_elongation_um);
    EXPECT_EQ(p1[q].mean.settle_time_s, p2[q].mean.settle_time_s);
    EXPECT_EQ(p1[q].stddev.max_elongation_um, p2[q].stddev.max_elongation_um);
    EXPECT_EQ(p1[q].stddev.settle_time_s, p2[q].stddev.settle_time_s);
  }
  SaveModel(Scratch("rt2.json"), back);
  EXPECT_EQ(ReadTextFile(Scratch("rt.json")), ReadTextFile(Scratch("rt2.json")));
  const auto j = ReadJsonFile(Scratch("rt.json"));
  EXPECT_EQ(j.at("error_space"), "normalized");
  EXPECT_EQ(j.at("layer_sizes"), nlohmann::json({5, 6, 2}));
  EXPECT_EQ(j.at("schema_version"), Model::kSchemaVersion);
}

// Schema 1 files (one noise level for both outputs) still load: both outputs get that level.
TEST(Model, SchemaOneFileLoadsWithOneNoiseLevelForBothOutputs) {
  const Model& m = SharedModel();
  nlohmann::json j = m;
  j["schema_version"] = 1;
  j["uncertainty"].erase("output_noise_variance_normalized");
  j["uncertainty"].erase("noise_calibration");
  WriteFileAtomic(Scratch("v1.json"), j.dump(1));
  const Model old = LoadModel(Scratch("v1.json"));
  EXPECT_EQ(old.output_noise_variance(0), m.noise_variance);
  EXPECT_EQ(old.output_noise_variance(1), m.noise_variance);
  const auto p = Predict(old, synth::SyntheticProcessTable(1, 0.0, 3).inputs[0]);
  EXPECT_GT(p.stddev.settle_time_s, 0);
}

TEST(Model, PredictMatchesScalingAndLaplaceFormulaByFiniteDifferences) {
  const Model& m = SharedModel();
  const ProcessTable queries = synth::SyntheticProcessTable(10, 0.0, 5);
  const auto preds = PredictBatch(m, queries.inputs);
  const Eigen::VectorXd half = m.target_scaling.HalfRange();
  for (std::size_t q = 0; q < preds.size(); ++q) {
    const Eigen::VectorXd x = m.input_scaling.Apply(InputMatrix({queries.inputs[q]}));
    const Eigen::VectorXd y = m.network.Forward(x);
    // mean: network output mapped back by mapminmax
    const Eigen::VectorXd mean = m.target_scaling.Reverse(y);
    EXPECT_NEAR(preds[q].mean.max_elongation_um, mean(0), 1e-12 * std::abs(mean(0)));
    EXPECT_NEAR(preds[q].mean.settle_time_s, mean(1), 1e-12 * std::abs(mean(1)));
    // g = dy/dw by central differences, var = sigma^2 + g' A^-1 g, std scaled by half range
    const Eigen::VectorXd w = m.network.GetParameters();
    Eigen::MatrixXd g(2, w.size());
    for (int i = 0; i < w.size(); ++i) {
      Network plus = m.network, minus = m.network;
      Eigen::VectorXd wp = w, wm = w;
      const double h = 1e-6 * std::max(1.0, std::abs(w(i)));
      wp(i) += h;
      wm(i) -= h;
      plus.SetParameters(wp);
      minus.SetParameters(wm);
      g.col(i) = (plus.Forward(x) - minus.Forward(x)) / (2 * h);
    }
    for (int k = 0; k < 2; ++k) {
      const double var =
          m.output_noise_variance(k) + g.row(k) * m.posterior_covariance * g.row(k).transpose();
      const double sd = std::sqrt(var) * half(k);
      const double got = k == 0 ? preds[q].stddev.max_elongation_um : preds[q].stddev.settle_time_s;
      EXPECT_NEAR(got, sd, 1e-6 * sd);
      const double noise =
          k == 0 ? preds[q].noise_stddev.max_elongation_um : preds[q].noise_stddev.settle_time_s;
      EXPECT_GE(got, noise);  // weight uncertainty only adds
      EXPECT_NEAR(noise, std::sqrt(m.output_noise_variance(k)) * half(k), 1e-12 * noise);
    }
  }
}

TEST(Model, UncertaintyGrowsFarOutsideTheTrainingDomainAndIsFlagged) {
  const Model& m = SharedModel();
  ProcessInputs inside;
  inside.hardness_hrc = 0.5 * (m.domain_min(0) + m.domain_max(0));
  inside.diameter_mm = 0.5 * (m.domain_min(1) + m.domain_max(1));
  inside.pitch_mm = 0.5 * (m.domain_min(2) + m.domain_max(2));
  inside.raceway_radius_mm = 0.5 * (m.domain_min(3) + m.domain_max(3));
  inside.cutting_speed_m_min = 0.5 * (m.domain_min(4) + m.domain_max(4));
  const Prediction pin = Predict(m, inside);
  EXPECT_FALSE(pin.outside_domain);
  EXPECT_TRUE(pin.outside_domain_fields.empty());
  ProcessInputs far = inside;
  far.diameter_mm = m.domain_max(1) + 10 * (m.domain_max(1) - m.domain_min(1));
  far.cutting_speed_m_min = m.domain_min(4) - 1;
  const Prediction pfar = Predict(m, far);
  EXPECT_TRUE(pfar.outside_domain);
  EXPECT_EQ(pfar.outside_domain_fields,
            (std::vector<std::string>{"diameter_mm", "cutting_speed_m_min"}));
  EXPECT_GT(pfar.stddev.max_elongation_um, pin.stddev.max_elongation_um);
  // Training-domain bounds are inclusive.
  ProcessInputs edge = inside;
  edge.pitch_mm = m.domain_max(2);
  EXPECT_FALSE(Predict(m, edge).outside_domain);
}

TEST(Model, TrainModelRejectsTablesWithoutTargetsOrRows) {
  ProcessTable t = synth::SyntheticProcessTable(20, 0.05, 1);
  t.targets.clear();
  EXPECT_THROW(TrainModel(t, ModelTrainOptions{}, "x"), InputError);
  t = synth::SyntheticProcessTable(1, 0.05, 1);
  EXPECT_THROW(TrainModel(t, ModelTrainOptions{}, "x"), InputError);
  t = synth::SyntheticProcessTable(20, 0.05, 1);
  ModelTrainOptions o;
  o.restarts = 0;
  EXPECT_THROW(TrainModel(t, o, "x"), InputError);
}

// Each corruption must be rejected with a message that names the key.
TEST(Model, LoadRejectsWrongTruncatedOrInconsistentFiles) {
  SaveModel(Scratch("good.json"), SharedModel());
  const std::string text = ReadTextFile(Scratch("good.json"));
  const nlohmann::json good = nlohmann::json::parse(text);
  struct Case {
    std::string name;
    std::function<void(nlohmann::json&)> corrupt;
    std::string expect;  // substring of the message
  };
  const std::vector<Case> cases = {
      {"schema version", [](auto& j) { j["schema_version"] = 99; }, "schema_version"},
      {"format", [](auto& j) { j["format"] = "other"; }, "format"},
      {"missing layers", [](auto& j) { j.erase("layers"); }, "layers"},
      {"layer sizes",
       [](auto& j) {
         j["layer_sizes"] = {5, 7, 2};
       },
       "layers[0].weights"},
      {"wrong input count", [](auto& j) { j["layer_sizes"][0] = 4; }, "layers[0].weights"},
      {"bias count", [](auto& j) { j["layers"][1]["biases"].push_back(1.0); }, "layers[1].biases"},
      {"non-number weight", [](auto& j) { j["layers"][0]["weights"][2][1] = "nan"; },
       "layers[0].weights[2][1]"},
      {"null weight", [](auto& j) { j["layers"][0]["biases"][0] = nullptr; },
       "layers[0].biases[0]"},
      {"scaling size", [](auto& j) { j["input_scaling"]["min"].erase(0); }, "input_scaling.min"},
      {"scaling order", [](auto& j) { j["target_scaling"]["min"][0] = 1e9; }, "target_scaling"},
      {"input name", [](auto& j) { j["inputs"][1]["name"] = "diameter_in"; }, "inputs[1]"},
      {"output unit", [](auto& j) { j["outputs"][1]["unit"] = "min"; }, "outputs[1]"},
      {"domain", [](auto& j) { j["training_domain"].erase("pitch_mm"); }, "training_domain"},
      {"unknown key", [](auto& j) { j["extra"] = 1; }, "extra"},
      {"error space", [](auto& j) { j["error_space"] = "original"; }, "error_space"},
      {"covariance size", [](auto& j) { j["uncertainty"]["posterior_covariance"].erase(0); },
       "posterior_covariance"},
      {"covariance symmetry",
       [](auto& j) { j["uncertainty"]["posterior_covariance"][0][1] = 12345.0; },
       "posterior_covariance"},
      {"noise", [](auto& j) { j["uncertainty"]["noise_variance_normalized"] = -1.0; },
       "noise_variance"},
      {"per-output noise",
       [](auto& j) { j["uncertainty"]["output_noise_variance_normalized"].erase(1); },
       "output_noise_variance"},
      {"schema", [](auto& j) { j["schema_version"] = 3; }, "schema_version"},
      {"summary", [](auto& j) { j["training_summary"].erase("gamma"); }, "gamma"},
      {"seed", [](auto& j) { j["seed"] = -3; }, "seed"},
  };
  for (const auto& c : cases) {
    nlohmann::json j = good;
    c.corrupt(j);
    WriteFileAtomic(Scratch("bad.json"), j.dump(1));
    try {
      LoadModel(Scratch("bad.json"));
      ADD_FAILURE() << c.name << ": accepted";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(c.expect), std::string::npos) << c.name << ": " << msg;
      EXPECT_NE(msg.find("bad.json"), std::string::npos) << c.name << ": " << msg;
    }
  }
  // Truncated file (a partial write): a JSON error naming the file.
  WriteFileAtomic(Scratch("trunc.json"), text.substr(0, text.size() / 2));
  try {
    LoadModel(Scratch("trunc.json"));
    ADD_FAILURE() << "truncated file accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("trunc.json"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadModel(Scratch("does_not_exist.json")), InputError);
}

TEST(HiddenSweep, ReportsEveryHiddenSizeWithConsistentNumbers) {
  const ProcessTable t = synth::SyntheticProcessTable(20, 0.05, 3);
  SweepOptions o;
  o.hidden_min = 2;
  o.hidden_max = 4;
  o.folds = 4;
  int last = 0;
  const auto rows = HiddenSweep(t, o, [&](int done, int total) {
    EXPECT_EQ(done, last + 1);
    EXPECT_EQ(total, 3 * 5);
    last = done;
  });
  ASSERT_EQ(rows.size(), 3u);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const int h = 2 + static_cast<int>(i);
    EXPECT_EQ(rows[i].hidden, h);
    EXPECT_EQ(rows[i].parameter_count, h * 6 + 2 * (h + 1));
    EXPECT_GT(rows[i].gamma, 0);
    EXPECT_LE(rows[i].gamma, rows[i].parameter_count);
    EXPECT_TRUE(rows[i].cv_rms.allFinite());
    EXPECT_TRUE(std::isfinite(rows[i].log_evidence));
    // Held-out error is not below the training error of the same size on average.
    EXPECT_GT(rows[i].cv_rms.sum(), 0.0);
  }
  EXPECT_EQ(last, 15);
  o.folds = 1;
  EXPECT_THROW(HiddenSweep(t, o), InputError);
  o.folds = 21;
  EXPECT_THROW(HiddenSweep(t, o), InputError);
}


// FlatOutputs: the collapsed fit predicts one value; the check compares the spread of
// the mean predictions with the spread of the targets over the training rows.
TEST(FlatOutputs, ConstantNetworkIsFlatInBothOutputsWithHandComputedTargetSd) {
  ProcessTable t = synth::SyntheticProcessTable(4, 0.0, 3);
  const double e[4] = {100, 110, 130, 140}, s[4] = {200, 200, 260, 260};
  for (int q = 0; q < 4; ++q) {
    t.targets[q].max_elongation_um = e[q];
    t.targets[q].settle_time_s = s[q];
  }
  Model m = SharedModel();
  m.network = Network::Zeros(m.network.layer_sizes);  // output = mid-range for every input
  const std::vector<FlatOutput> flat = FlatOutputs(m, t);
  ASSERT_EQ(flat.size(), 2u);
  EXPECT_EQ(flat[0].output, 0);
  EXPECT_EQ(flat[1].output, 1);
  // population sd: elongation mean 120, deviations -20 -10 10 20 -> sqrt(1000 / 4); settle 30
  EXPECT_NEAR(flat[0].target_sd, std::sqrt(250.0), 1e-12);
  EXPECT_NEAR(flat[1].target_sd, 30.0, 1e-12);
  EXPECT_LT(flat[0].prediction_sd, 1e-12);
  EXPECT_LT(flat[0].spread_ratio, 1e-12);
  const std::string text = DescribeFlatOutputs(m, flat);
  EXPECT_NE(text.find("max_elongation_um and settle_time_s"), std::string::npos) << text;
  EXPECT_NE(text.find("gamma"), std::string::npos) << text;
}

TEST(FlatOutputs, FittedSmoothTableIsNotFlatAndZeroedOutputRowIsTheOnlyFlatOne) {
  const ProcessTable t = synth::SyntheticProcessTable(20, 0.05, 1);
  EXPECT_TRUE(FlatOutputs(SharedModel(), t).empty());
  Model m = SharedModel();
  const int L = m.network.LayerCount();
  m.network.weights[L - 1].row(1).setZero();  // settle time = its output bias for every input
  const std::vector<FlatOutput> flat = FlatOutputs(m, t);
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_EQ(flat[0].output, 1);
  EXPECT_LT(flat[0].spread_ratio, 1e-12);  // one value, up to the rounding of its mean
  // output weights shrunk 1000-fold: the output layer is linear and mapminmax affine, so the
  // elongation's spread ratio shrinks 1000-fold too (from above 0.3 to below kFlatSpreadRatio)
  Model tiny = SharedModel();
  tiny.network.weights[L - 1].row(0) *= 1e-3;
  const std::vector<FlatOutput> shrunk = FlatOutputs(tiny, t);
  ASSERT_EQ(shrunk.size(), 1u);
  EXPECT_EQ(shrunk[0].output, 0);
  EXPECT_GT(shrunk[0].spread_ratio, 0.0);
  EXPECT_LT(shrunk[0].spread_ratio, 1e-3);
}

TEST(FlatOutputs, ConstantTargetsAreSkippedAndTargetlessTableIsRejected) {
  ProcessTable t = synth::SyntheticProcessTable(6, 0.0, 4);
  for (auto& f : t.targets) f.settle_time_s = 300;
  Model m = SharedModel();
  m.network = Network::Zeros(m.network.layer_sizes);
  const std::vector<FlatOutput> flat = FlatOutputs(m, t);
  ASSERT_EQ(flat.size(), 1u);
  EXPECT_EQ(flat[0].output, 0);
  t.targets.clear();
  EXPECT_THROW(FlatOutputs(m, t), InputError);
}

// Targets that do not depend on the inputs (uniform draws): every hidden size collapses to the
// same flat function, so the check flags it and, with the symmetry term counting only active
// neurons (ActiveHiddenUnits), the log evidence no longer depends on the size. Before that
// correction 8 neurons got ln(2^8 8!) - ln(2^4 4!) = 10.2 more than 4 for the same function.
TEST(FlatOutputs, CollapsedFitsOfEverySizeAreFlaggedAndHaveTheSameEvidence) {
  ProcessTable t = synth::SyntheticProcessTable(20, 0.0, 2);
  Rng rng(102);
  for (auto& f : t.targets) {
    f.max_elongation_um = 50 + 10 * rng.Uniform();
    f.settle_time_s = 300 + 60 * rng.Uniform();
  }
  std::vector<double> evidence;
  for (int h : {4, 6, 8}) {
    ModelTrainOptions o = DefaultTrainingOptions();
    o.hidden_candidates.clear();
    o.hidden_sizes = {h};
    o.noise_folds = 0;
    o.threads = 1;
    const Model m = TrainModel(t, o, "noise");
    ASSERT_EQ(FlatOutputs(m, t).size(), 2u) << h << " neurons, gamma " << m.training_summary.gamma;
    evidence.push_back(m.training_summary.log_evidence);
  }
  EXPECT_NEAR(evidence[1], evidence[0], 1e-3);
  EXPECT_NEAR(evidence[2], evidence[0], 1e-3);
}


// Default training includes a linear network (no hidden layer) among the sizes by
// evidence: on a table whose targets are linear in the inputs plus noise it has the highest
// evidence, depends on the inputs, round-trips through the model file and predicts the truth.
TEST(HiddenByEvidence, LinearTruthGivesTheLinearNetwork) {
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    ProcessTable t = synth::SyntheticProcessTable(20, 0.0, seed);
    Rng rng(200 + seed);
    auto truth = [](const ProcessInputs& in) {
      return Features{2.0 * in.hardness_hrc + 0.5 * in.diameter_mm - 3.0 * in.pitch_mm + 100,
                      0.8 * in.cutting_speed_m_min + 4.0 * in.raceway_radius_mm + 50};
    };
    for (std::size_t q = 0; q < t.inputs.size(); ++q) {
      t.targets[q] = truth(t.inputs[q]);
      t.targets[q].max_elongation_um += 0.5 * synth::Gaussian(&rng);
      t.targets[q].settle_time_s += 1.0 * synth::Gaussian(&rng);
    }
    ModelTrainOptions o = DefaultTrainingOptions();
    o.seed = seed;
    o.threads = 1;
    const Model m = TrainModel(t, o, "linear.csv");
    ASSERT_EQ(m.network.layer_sizes, (std::vector<int>{5, 2})) << m.hidden_selection;
    EXPECT_NE(m.hidden_selection.find("hidden size 0 of the highest log evidence"),
              std::string::npos) << m.hidden_selection;
    EXPECT_TRUE(FlatOutputs(m, t).empty());
    const fs::path file = Scratch("linear" + std::to_string(seed) + ".json");
    SaveModel(file, m);
    const Model back = LoadModel(file);
    const ProcessTable probe = synth::SyntheticProcessTable(50, 0.0, 40 + seed);
    const std::vector<Prediction> p = PredictBatch(back, probe.inputs);
    for (std::size_t q = 0; q < p.size(); ++q) {
      const Features f = truth(probe.inputs[q]);
      EXPECT_NEAR(p[q].mean.max_elongation_um, f.max_elongation_um, 1.5) << q;
      EXPECT_NEAR(p[q].mean.settle_time_s, f.settle_time_s, 3.0) << q;
    }
  }
}

}  // namespace
}  // namespace whirl::nn
