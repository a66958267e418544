// workpiece/model.h: one prediction for a network and a family choice (mean, delta-method sd,
// training-domain guard), the model files (round trip, the shipped network files, bad files),
// the "not a network" error, training by the flags, and the choice against the power law.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/json_file.h"
#include "support/expect_error.h"
#include "support/power_law_table.h"
#include "support/scratch_dir.h"
#include "workpiece/model.h"

namespace whirl::workpiece {
namespace {

namespace fs = std::filesystem;
using test::MakeTable;

fs::path Scratch(const std::string& name) {
  const fs::path dir = whirl::test::ScratchDir() / "whirl_test_workpiece";
  fs::create_directories(dir);
  return dir / name;
}

WorkpieceModel DefaultModel(const ProcessTable& table) {
  return TrainWorkpieceModel(table, {}, "generated.csv");
}

std::string Shipped(const std::string& relative) {
  return std::string(WHIRL_SOURCE_DIR) + "/" + relative;
}

TEST(WorkpieceModel, FamilyFileRoundTripPredictsBitIdentically) {
  const ProcessTable train = MakeTable(20, 0.05, 11, true), test = MakeTable(30, 0.0, 12, true);
  const WorkpieceModel m = DefaultModel(train);
  ASSERT_FALSE(m.IsNetwork());
  SaveWorkpieceModel(Scratch("family.json"), m);
  const WorkpieceModel back = LoadWorkpieceModel(Scratch("family.json"));
  ASSERT_FALSE(back.IsNetwork());
  EXPECT_EQ(back.Describe(), m.Describe());
  EXPECT_EQ(back.training_samples, 20);
  EXPECT_EQ(ReadJsonFile(Scratch("family.json")).at("schema_version"), 3);
  const std::vector<Prediction> a = PredictBatch(m, test.inputs), b = PredictBatch(back, test.inputs);
  for (std::size_t q = 0; q < a.size(); ++q)
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(a[q].mean.ToArray()[k], b[q].mean.ToArray()[k]);
      EXPECT_EQ(a[q].stddev.ToArray()[k], b[q].stddev.ToArray()[k]);
    }
  // Writing the reloaded model gives the same file.
  SaveWorkpieceModel(Scratch("family2.json"), back);
  EXPECT_EQ(ReadJsonFile(Scratch("family.json")), ReadJsonFile(Scratch("family2.json")));
}

TEST(WorkpieceModel, ShippedNetworkFileLoadsAndPredictsAsTheNetwork) {
  const std::string path = Shipped("models/default.json");
  const WorkpieceModel m = LoadWorkpieceModel(path);
  ASSERT_TRUE(m.IsNetwork());
  EXPECT_EQ(m.Describe(), "network 5-6-2");
  const nn::Model net = nn::LoadModel(path);
  const ProcessInputs in{62, 80, 10, 3.7, 180}, out{62, 80, 10, 3.7, 400};
  for (const ProcessInputs& x : {in, out}) {
    const Prediction p = Predict(m, x), r = nn::Predict(net, x);
    EXPECT_EQ(p.mean.max_elongation_um, r.mean.max_elongation_um);
    EXPECT_EQ(p.stddev.settle_time_s, r.stddev.settle_time_s);
    EXPECT_EQ(p.outside_domain, r.outside_domain);
  }
  EXPECT_TRUE(Predict(m, out).outside_domain);
  // Saving it writes the network file byte for byte.
  SaveWorkpieceModel(Scratch("network.json"), m);
  std::ifstream a(path), b(Scratch("network.json"));
  const std::string sa((std::istreambuf_iterator<char>(a)), {}),
      sb((std::istreambuf_iterator<char>(b)), {});
  EXPECT_EQ(sa, sb);
}

TEST(WorkpieceModel, NetworkOnRawColumnsIsTheNetworkOfEarlierVersions) {
  const ProcessTable train = MakeTable(20, 0.05, 5);
  TrainOptions o;
  o.family = FamilyFlag::kNetwork;
  o.transform = TransformFlag::kIdentity;
  o.network = nn::ModelTrainOptions{};  // --trainbr-matlab: 5-6-2 to MATLAB's criteria
  const WorkpieceModel m = TrainWorkpieceModel(train, o, "generated.csv");
  ASSERT_TRUE(m.IsNetwork());
  const nn::Model direct = nn::TrainModel(train, nn::ModelTrainOptions{}, "generated.csv");
  EXPECT_EQ(nlohmann::json(m.network), nlohmann::json(direct));
}

TEST(WorkpieceModel, DomainGuardNamesTheInputsOutsideTheTrainingRanges) {
  const ProcessTable train = MakeTable(20, 0.02, 21);
  const WorkpieceModel m = DefaultModel(train);
  ProcessInputs x = train.inputs[3];
  EXPECT_FALSE(Predict(m, x).outside_domain);
  x.diameter_mm = m.domain_max(1) * 1.01;
  x.cutting_speed_m_min = m.domain_min(4) * 0.99;
  const Prediction p = Predict(m, x);
  EXPECT_TRUE(p.outside_domain);
  EXPECT_EQ(p.outside_domain_fields, (std::vector<std::string>{"diameter_mm", "cutting_speed_m_min"}));
  const nn::OutsideDomainSummary s = SummarizeOutsideDomain({p, Predict(m, train.inputs[0])});
  EXPECT_EQ(s.rows, 1);
  EXPECT_EQ(s.per_input[1], 1);
  EXPECT_EQ(s.per_input[4], 1);
  EXPECT_EQ(s.per_input[0], 0);
}

// sd of a log output = d exp(z)/dz at the mean times the sd in log units: against a central finite
// difference of the back-mapped mean when the transformed mean is shifted by +-h.
TEST(WorkpieceModel, DeltaMethodSdMatchesFiniteDifferencesOfTheBackMapping) {
  const ProcessTable train = MakeTable(20, 0.05, 31);
  TrainOptions o;
  o.family = FamilyFlag::kLinear;
  o.transform = TransformFlag::kLog;
  const WorkpieceModel m = TrainWorkpieceModel(train, o, "generated.csv");
  const family::FamilyModel& f = m.choice.models.front();
  const ProcessTable test = MakeTable(10, 0.0, 32);
  const Eigen::MatrixXd z = family::TransformInputs(f.transform, nn::InputMatrix(test.inputs));
  for (int k = 0; k < 2; ++k) {
    const family::LinearPrediction lp = family::PredictLinear(f.linears[k], z);
    for (std::size_t q = 0; q < test.inputs.size(); ++q) {
      const double mz = lp.mean(q);
      const double sz = std::sqrt(lp.latent_variance(q) + f.linears[k].noise_variance);
      const double h = 1e-5;
      const double slope = (std::exp(mz + h) - std::exp(mz - h)) / (2 * h);
      const Prediction p = Predict(m, test.inputs[q]);
      EXPECT_NEAR(p.mean.ToArray()[k], std::exp(mz), 1e-12 * std::exp(mz));
      const double scale = m.choice.sd_scale[k];  // ChoiceOptions::stack_scale_single
      EXPECT_NEAR(p.stddev.ToArray()[k], scale * slope * sz, 1e-6 * scale * slope * sz);
    }
  }
}

TEST(WorkpieceModel, NotANetworkForCrosscheckAndExport) {
  const WorkpieceModel m = DefaultModel(MakeTable(20, 0.05, 41));
  const fs::path path = Scratch("not_a_network.json");
  SaveWorkpieceModel(path, m);
  ExpectInputError([&] { LoadNetworkModel(path, "crosscheck"); }, "not a network");
  ExpectInputError([&] { LoadNetworkModel(path, "export"); }, path.string());
  EXPECT_EQ(LoadNetworkModel(Shipped("models/default.json"), "export").network.layer_sizes,
            (std::vector<int>{5, 6, 2}));
}

TEST(WorkpieceModel, BadFamilyFilesNameTheFileAndTheKey) {
  const WorkpieceModel m = DefaultModel(MakeTable(20, 0.05, 51));
  const nlohmann::json good = ReadJsonFile((SaveWorkpieceModel(Scratch("good.json"), m),
                                            Scratch("good.json")));
  const auto expect_bad = [&](const std::function<void(nlohmann::json&)>& edit,
                              const std::string& fragment) {
    nlohmann::json j = good;
    edit(j);
    WriteJsonFile(Scratch("bad.json"), j);
    ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad.json")); }, fragment);
    ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad.json")); }, "bad.json");
  };
  expect_bad([](nlohmann::json& j) { j["schema_version"] = 4; }, "schema_version");
  expect_bad([](nlohmann::json& j) { j["kind"] = "network"; }, "kind");
  expect_bad([](nlohmann::json& j) { j["domain"]["min"] = {1, 2}; }, "domain.min");
  expect_bad([](nlohmann::json& j) { j["choice"]["chosen"] = {0, 99}; }, "chosen");
  expect_bad([](nlohmann::json& j) { j["choice"]["models"][0]["candidate"] = "svm/log"; },
             "candidate 'svm/log'");
  expect_bad([](nlohmann::json& j) { j["choice"].erase("models"); }, "models");
  expect_bad([](nlohmann::json& j) { j["extra"] = 1; }, "extra");
  expect_bad([](nlohmann::json& j) { j["inputs"][0]["name"] = "hardness"; }, "inputs");
  expect_bad([](nlohmann::json& j) { j["domain"]["max"][0] = 1e9; },
             "'domain.max': hardness_hrc = 1e+09 breaks the rule");
  expect_bad([](nlohmann::json& j) { j["choice"]["table"][0]["cv_rmse"][0] = -1; },
             "cv_rmse[0] = -1 breaks the rule");
  expect_bad([](nlohmann::json& j) { j["choice"]["table"][0]["score"] = 1e300; },
             "score = 1e+300 breaks the rule");
}

// Numbers of a model file get the range checks of a flag (the message names the file, the field
// and the rule), and a file whose numbers pass every rule but predict nonsense at the training
// domain is refused too: a GP target_scale of 1e308 predicted 0 with sd nan, a noise variance of
// 1e308 an sd of 6e154, and `plan` wrote a program from them.
TEST(WorkpieceModel, FileNumbersAreRangeCheckedAndPredictionsMustBeFinite) {
  TrainOptions o;
  o.family = FamilyFlag::kGaussianProcess;
  o.transform = TransformFlag::kIdentity;
  const WorkpieceModel gp = TrainWorkpieceModel(MakeTable(20, 0.05, 52), o, "generated.csv");
  const nlohmann::json good = ReadJsonFile((SaveWorkpieceModel(Scratch("gp.json"), gp),
                                            Scratch("gp.json")));
  const auto expect_bad = [&](const char* key, double value, const std::string& fragment) {
    nlohmann::json j = good;
    j["choice"]["models"][0]["gps"][1][key] = value;
    WriteJsonFile(Scratch("bad_gp.json"), j);
    ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad_gp.json")); }, fragment);
    ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad_gp.json")); }, "bad_gp.json");
  };
  expect_bad("target_scale", 1e308,
             "'gps'[1] (settle_time_s): gaussian process: target_scale = 1e+308 breaks the "
             "rule: must lie in (0, 1e+07]");
  expect_bad("noise_variance", 1e308, "noise_variance = 1e+308 breaks the rule");
  expect_bad("min_noise_variance", 0.0, "min_noise_variance = 0 breaks the rule");
  expect_bad("target_shift", -2e7, "target_shift = -2e+07 breaks the rule");
  nlohmann::json j = good;
  j["choice"]["models"][0]["gps"][0]["theta"][2] = 31.0;
  WriteJsonFile(Scratch("bad_gp.json"), j);
  ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad_gp.json")); },
                   "theta[2] = 31 breaks the rule: must lie in [-30, 30]");
  // Within every field rule, but the signal sd e^29 times the target sd of 1e5 predicts an sd
  // far beyond any elongation.
  j = good;
  j["choice"]["models"][0]["gps"][0]["theta"][5] = 29.0;
  j["choice"]["models"][0]["gps"][0]["target_scale"] = 1e5;
  WriteJsonFile(Scratch("bad_gp.json"), j);
  ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad_gp.json")); },
                   "'choice.models'[0] (gp-matern52-constant/identity) predicts "
                   "max_elongation_um = ");
  // A network file: weights and noise levels beyond their bounds.
  nlohmann::json net = ReadJsonFile(Shipped("models/default.json"));
  net["layers"][0]["weights"][1][2] = 1e300;
  WriteJsonFile(Scratch("bad_net.json"), net);
  ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad_net.json")); },
                   "model 'layers[0].weights[1][2]' = 1e+300 breaks the rule: |x| <= 1e+06");
  net = ReadJsonFile(Shipped("models/default.json"));
  net["uncertainty"]["output_noise_variance_normalized"][1] = 1e308;
  WriteJsonFile(Scratch("bad_net.json"), net);
  ExpectInputError([&] { LoadWorkpieceModel(Scratch("bad_net.json")); },
                   "output_noise_variance_normalized[1]' = 1e+308 breaks the rule");
}

// The legend's family words: the shipped network, a power law (linear/log), a GP.
TEST(WorkpieceModel, FamilyLabelNamesTheChosenFamily) {
  EXPECT_EQ(LoadWorkpieceModel(Shipped("models/default.json")).FamilyLabel(), "network");
  const ProcessTable t = MakeTable(20, 0.05, 21);
  TrainOptions power;
  power.family = FamilyFlag::kLinear;
  power.transform = TransformFlag::kLog;
  const WorkpieceModel p = TrainWorkpieceModel(t, power, "generated.csv");
  ASSERT_EQ(p.Describe(), "max_elongation_um: linear/log, settle_time_s: linear/log");
  EXPECT_EQ(p.FamilyLabel(), "power law");
  TrainOptions gp;
  gp.family = FamilyFlag::kGaussianProcess;
  gp.transform = TransformFlag::kIdentity;
  EXPECT_EQ(TrainWorkpieceModel(t, gp, "generated.csv").FamilyLabel(), "Gaussian process");
}

TEST(WorkpieceTraining, FlagsSelectTheCandidates) {
  const auto names = [](FamilyFlag f, TransformFlag t) {
    std::string s;
    for (const family::Candidate& c : Candidates(f, t)) s += c.Name() + " ";
    return s;
  };
  EXPECT_EQ(names(FamilyFlag::kLinear, TransformFlag::kAuto), "linear/log linear/identity ");
  EXPECT_EQ(names(FamilyFlag::kGaussianProcess, TransformFlag::kLog), "gp-matern52-linear/log ");
  EXPECT_EQ(names(FamilyFlag::kNetwork, TransformFlag::kLog), "network-evidence/log ");
  EXPECT_EQ(names(FamilyFlag::kAuto, TransformFlag::kIdentity),
            "linear/identity gp-matern52-constant/identity gp-se-constant/identity "
            "network-h2/identity ");
  ExpectInputError([] { ParseFamilyFlag("svm"); }, "--family 'svm'");
  ExpectInputError([] { ParseTransformFlag("sqrt"); }, "--transform 'sqrt'");
}

// On tables that follow a power law, the default's chosen model is never worse in cross-validated
// error than the power law itself, output by output.
TEST(WorkpieceTraining, ChosenNeverWorseInCvThanThePowerLawOnPowerLawTables) {
  for (unsigned seed = 100; seed < 115; ++seed) {
    const WorkpieceModel m = DefaultModel(MakeTable(20 + static_cast<int>(seed % 3) * 20, 0.05, seed));
    const family::Choice& c = m.choice;
    const auto power_law = std::find_if(c.table.begin(), c.table.end(), [](const auto& r) {
      return r.candidate.Name() == "linear/log";
    });
    ASSERT_NE(power_law, c.table.end());
    for (int k = 0; k < 2; ++k)
      EXPECT_LE(c.table[c.chosen[k]].cv_rmse(k), power_law->cv_rmse(k) * (1 + 1e-12))
          << "seed " << seed << ": " << c.Describe();
  }
}

// Property: every --family flag, with the stack and the hard choice, on random tables of 8, 20,
// 69, 70 and 100 rows (below, at and above ChoiceOptions::few_rows; power laws, smooth non-power
// laws, Friedman #2/#3), gives a model with finite predictions at its training rows or an
// InputError that names the table; never an error of the choice's internals (such as
// "stacking weights: 100 x 0 predictions" of --family gp on Friedman #2/#3 tables).
TEST(WorkpieceTraining, EveryFamilyFlagGivesAModelOrAnErrorNamingTheTable) {
  const std::string name = "random_table.csv";
  int models = 0;
  for (unsigned seed = 1; seed <= 15; ++seed) {
    const int rows = std::array<int, 5>{8, 20, 69, 70, 100}[seed % 5];
    const ProcessTable table = seed % 3 == 0   ? test::MakeFriedman23Table(rows, seed)
                               : seed % 3 == 1 ? MakeTable(rows, 0.05, seed, true)
                                               : MakeTable(rows, 0.1, seed);
    for (FamilyFlag f : {FamilyFlag::kAuto, FamilyFlag::kNetwork, FamilyFlag::kGaussianProcess,
                         FamilyFlag::kLinear})
      for (bool stack : {true, false}) {
        TrainOptions o;
        o.family = f;
        o.choice.stack = stack;
        const std::string what = "seed " + std::to_string(seed) + ", " + std::to_string(rows) +
                                 " rows, family " + std::to_string(static_cast<int>(f)) +
                                 (stack ? ", stack" : ", hard");
        try {
          const WorkpieceModel m = TrainWorkpieceModel(table, o, name);
          for (const Prediction& p : PredictBatch(m, table.inputs))
            for (double v : {p.mean.max_elongation_um, p.mean.settle_time_s,
                             p.stddev.max_elongation_um, p.stddev.settle_time_s})
              ASSERT_TRUE(std::isfinite(v)) << what;
          ++models;
        } catch (const InputError& e) {
          EXPECT_NE(std::string(e.what()).find(name), std::string::npos)
              << what << ": " << e.what();
        }
      }
  }
  EXPECT_GE(models, 100) << "of 120 trainings";
}

}  // namespace
}  // namespace whirl::workpiece
