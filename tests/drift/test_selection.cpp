// Miao et al.'s sensitive-point selection: fuzzy equivalence properties, nested lambda-cuts, the F
// statistic and the grey grade against hand-computed examples, planted clusters.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "core/error.h"
#include "drift/selection.h"
#include "synthetic.h"

namespace whirl::drift {
namespace {

Eigen::MatrixXd RandomSimilarity(std::mt19937_64& rng, int m) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::MatrixXd r = Eigen::MatrixXd::Identity(m, m);
  for (int i = 0; i < m; ++i)
    for (int j = i + 1; j < m; ++j) r(i, j) = r(j, i) = u(rng);
  return r;
}

TEST(FuzzyEquivalence, ReflexiveSymmetricTransitiveIdempotentOnRandomInputs) {
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 200; ++trial) {
    const int m = 2 + trial % 14;
    Eigen::MatrixXd s;
    if (trial % 2 == 0) {
      s = RandomSimilarity(rng, m);
    } else {  // from random series, as the selection builds it
      std::normal_distribution<double> n(0.0, 1.0);
      Eigen::MatrixXd x(30, m);
      for (int i = 0; i < x.size(); ++i) x.data()[i] = n(rng);
      s = SimilarityMatrix(x);
    }
    int squarings = 0;
    const Eigen::MatrixXd r = FuzzyEquivalence(s, &squarings);
    EXPECT_LE(squarings, static_cast<int>(std::ceil(std::log2(m))) + 1);
    for (int i = 0; i < m; ++i) {
      EXPECT_EQ(r(i, i), 1.0);
      for (int j = 0; j < m; ++j) {
        EXPECT_EQ(r(i, j), r(j, i));
        EXPECT_GE(r(i, j), s(i, j));  // the closure contains the relation
        for (int k = 0; k < m; ++k) EXPECT_GE(r(i, j), std::min(r(i, k), r(k, j)));
      }
    }
    EXPECT_EQ(MaxMinCompose(r, r), r);
  }
}

TEST(FuzzyEquivalence, ClosureOfAChainIsItsWeakestLink) {
  // 0-1 at 0.9, 1-2 at 0.8, 0-2 at 0.1: the closure lifts 0-2 to min(0.9, 0.8) = 0.8.
  Eigen::MatrixXd s(3, 3);
  s << 1, 0.9, 0.1, 0.9, 1, 0.8, 0.1, 0.8, 1;
  const Eigen::MatrixXd r = FuzzyEquivalence(s);
  EXPECT_EQ(r(0, 2), 0.8);
  EXPECT_EQ(LambdaLevels(r), (std::vector<double>{0.9, 0.8}));
  EXPECT_EQ(LambdaCut(r, 0.9), (std::vector<int>{0, 0, 1}));
  EXPECT_EQ(LambdaCut(r, 0.8), (std::vector<int>{0, 0, 0}));
}

TEST(LambdaCut, PartitionsAreNestedOnRandomInputs) {
  std::mt19937_64 rng(11);
  for (int trial = 0; trial < 100; ++trial) {
    const int m = 3 + trial % 12;
    const Eigen::MatrixXd r = FuzzyEquivalence(RandomSimilarity(rng, m));
    const std::vector<double> levels = LambdaLevels(r);
    for (std::size_t l = 1; l < levels.size(); ++l) {
      const auto fine = LambdaCut(r, levels[l - 1]), coarse = LambdaCut(r, levels[l]);
      for (int i = 0; i < m; ++i)
        for (int j = 0; j < m; ++j)
          if (fine[i] == fine[j]) {
            EXPECT_EQ(coarse[i], coarse[j]) << "a lower lambda split a class";
          }
      const int nf = *std::max_element(fine.begin(), fine.end());
      const int nc = *std::max_element(coarse.begin(), coarse.end());
      EXPECT_LT(nc, nf);  // every distinct level merges at least two classes
    }
    if (!levels.empty()) {  // the lowest level is one class
      const auto last = LambdaCut(r, levels.back());
      EXPECT_EQ(*std::max_element(last.begin(), last.end()), 0);
    }
  }
}

TEST(FStatistic, HandComputedExample) {
  // z columns (1,0), (3,0), (0,2), (0,4) in classes {0,1} {2,3}: zbar = (1, 1.5), class means
  // (2,0), (0,3); between = 2 (1 + 2.25) + 2 (1 + 2.25) = 13 over r - 1 = 1; within = 4 over
  // m - r = 2; F = 13 / 2 = 6.5.
  Eigen::MatrixXd z(2, 4);
  z << 1, 3, 0, 0, 0, 0, 2, 4;
  EXPECT_DOUBLE_EQ(FStatistic(z, {0, 0, 1, 1}), 6.5);
  // Tight classes: the denominator is 0 and F is infinite.
  Eigen::MatrixXd tight(2, 3);
  tight << 1, 1, 0, 0, 0, 1;
  EXPECT_TRUE(std::isinf(FStatistic(tight, {0, 0, 1})));
}

TEST(FStatistic, CriticalValuesMatchTables) {
  // Standard F tables (upper 5 % and 1 % points).
  EXPECT_NEAR(FCritical(2, 10, 0.05), 4.1028, 1e-4);
  EXPECT_NEAR(FCritical(1, 5, 0.05), 6.6079, 1e-4);
  EXPECT_NEAR(FCritical(3, 12, 0.01), 5.9526, 1e-4);
}

TEST(GreyGrade, HandComputedExample) {
  // x0 = (0,1,2) -> (0, .5, 1); x1 identical -> d = 0; x2 = (0,2,1) -> (0, 1, .5), d = (0, .5,
  // .5). d_min = 0, d_max = .5, rho d_max = .25: grade1 = 1, grade2 = (1 + 1/3 + 1/3) / 3 = 5/9.
  Eigen::MatrixXd x(3, 2);
  x << 0, 0, 1, 2, 2, 1;
  Eigen::VectorXd e(3);
  e << 0, 1, 2;
  const Eigen::VectorXd g = GreyGrades(x, e, 0.5);
  EXPECT_DOUBLE_EQ(g(0), 1.0);
  EXPECT_NEAR(g(1), 5.0 / 9.0, 1e-15);
}

TEST(Similarity, ConstantSensorIsSimilarToNothing) {
  Eigen::MatrixXd x(4, 3);
  x << 0, 1, 0, 1, 1, 2, 2, 1, 4, 3, 1, 6;
  const Eigen::MatrixXd s = SimilarityMatrix(x);
  EXPECT_EQ(s(1, 0), 0.0);
  EXPECT_EQ(s(1, 2), 0.0);
  EXPECT_EQ(s(1, 1), 1.0);
  EXPECT_NEAR(s(0, 2), 1.0, 1e-12);  // x2 = 2 x0
}

TEST(Selection, RecoversPlantedClusters) {
  // Three groups of three sensors sharing a latent temperature; the error is driven by groups
  // 0 and 2. The chosen partition is the planted one and one sensor per group is chosen.
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const drift::Run run = synth::PlantedRun(seed, 3, 3, {2.0, 0.0, -1.5});
    SelectionOptions o;
    o.rule = ClassCountRule::kLargestMargin;
    const Selection s = SelectSensors({run}, "e_um", o);
    ASSERT_GE(s.chosen_partition, 0) << s.message;
    const auto& labels = s.partitions[static_cast<std::size_t>(s.chosen_partition)].labels;
    EXPECT_EQ(labels, (std::vector<int>{0, 0, 0, 1, 1, 1, 2, 2, 2})) << "seed " << seed;
    ASSERT_EQ(s.chosen.size(), 3u);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(s.chosen[static_cast<std::size_t>(k)] / 3, k);
    // The paper's rule (fewest significant classes) picks a coarser or equal nested cut.
    const Selection fewest = SelectSensors({run}, "e_um", SelectionOptions{});
    ASSERT_GE(fewest.chosen_partition, 0);
    EXPECT_GE(fewest.chosen_partition, 0);
    EXPECT_LE(fewest.partitions[static_cast<std::size_t>(fewest.chosen_partition)].classes, 3);
  }
}

TEST(Selection, FixedAndCappedClassCounts) {
  const drift::Run run = synth::PlantedRun(3, 3, 3, {2.0, 1.0, -1.5});
  SelectionOptions o;
  o.rule = ClassCountRule::kFixed;
  o.fixed_classes = 3;
  EXPECT_EQ(SelectSensors({run}, "e_um", o).chosen.size(), 3u);
  o.fixed_classes = 99;
  EXPECT_THROW(SelectSensors({run}, "e_um", o), InputError);
  SelectionOptions capped;
  capped.rule = ClassCountRule::kLargestMargin;
  capped.max_classes = 2;
  EXPECT_LE(SelectSensors({run}, "e_um", capped).chosen.size(), 2u);
}

}  // namespace
}  // namespace whirl::drift
