// Tests of src/product/design: the first design against a known optimum and random subsets, the exact
// variance update against a refit, and the next screws' invariants on a trained model.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "core/error.h"
#include "core/process.h"
#include "design/design.h"
#include "family/family.h"
#include "family/linear.h"
#include "gp/gp.h"
#include "workpiece/model.h"

namespace whirl::design {
namespace {

InputRanges PaperRanges() {
  InputRanges r;
  r.lo = {60, 50, 6, 3, 150};
  r.hi = {65, 100, 16, 10, 210};
  return r;
}

// ln det(F'F) of the power law's rows (1, ln x standardized over `all`) of `picked`.
double LogDet(const std::vector<ProcessInputs>& all, const std::vector<int>& picked) {
  Eigen::MatrixXd f(all.size(), 6);
  for (std::size_t c = 0; c < all.size(); ++c) {
    const auto a = all[c].ToArray();
    f(c, 0) = 1;
    for (int j = 0; j < 5; ++j) f(c, j + 1) = std::log(a[j]);
  }
  for (int j = 1; j < 6; ++j) {
    const double m = f.col(j).mean();
    const double s = std::sqrt((f.col(j).array() - m).square().mean());
    f.col(j) = (f.col(j).array() - m) / s;
  }
  Eigen::MatrixXd m = Eigen::MatrixXd::Zero(6, 6);
  for (int i : picked) m += f.row(i).transpose() * f.row(i);
  return std::log(m.determinant());
}

TEST(Design, GridSpansTheRangesInLogSteps) {
  const auto g = GridCandidates(PaperRanges(), 3);
  ASSERT_EQ(g.size(), 243u);
  EXPECT_DOUBLE_EQ(g[0].diameter_mm, 50);
  EXPECT_DOUBLE_EQ(g.back().diameter_mm, 100);
  EXPECT_NEAR(g[27].diameter_mm, std::sqrt(50.0 * 100.0), 1e-9);  // the geometric middle
}

TEST(Design, DOptimalOnTheGridIsTheFullFactorial) {
  // For a first-order model on a box the 2^5 corners are D-optimal (Box & Hunter 1961); on the
  // 3-level grid in log steps the same holds for the power law on log inputs.
  const auto g = GridCandidates(PaperRanges(), 3);
  const auto d = DesignPowerLaw(g, 32, Criterion::kD);
  std::set<int> picked;
  for (const auto& p : d.picks) picked.insert(p.candidate);
  ASSERT_EQ(picked.size(), 32u);
  const auto r = PaperRanges();
  for (int c : picked) {
    const auto a = g[c].ToArray();
    for (int j = 0; j < 5; ++j)
      EXPECT_TRUE(a[j] == r.lo[j] || a[j] == r.hi[j]) << "candidate " << c << " input " << j;
  }
}

TEST(Design, DesignBeatsRandomSubsetsOfTheList) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<ProcessInputs> cands;
  for (int i = 0; i < 60; ++i)
    cands.push_back(ProcessInputs::FromArray(
        {60 + 5 * u(rng), 50 + 50 * u(rng), 6 + 10 * u(rng), 3 + 7 * u(rng), 150 + 60 * u(rng)}));
  for (int count : {6, 10}) {
    const auto d = DesignPowerLaw(cands, count, Criterion::kD);
    std::vector<int> picked;
    for (const auto& p : d.picks) picked.push_back(p.candidate);
    const double best = LogDet(cands, picked);
    std::vector<int> idx(cands.size());
    for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = static_cast<int>(i);
    for (int t = 0; t < 300; ++t) {
      std::shuffle(idx.begin(), idx.end(), rng);
      EXPECT_GE(best, LogDet(cands, {idx.begin(), idx.begin() + count}) - 1e-9);
    }
    // Distinct candidates, and the reported criterion is this one per screw.
    EXPECT_EQ(std::set<int>(picked.begin(), picked.end()).size(), picked.size());
    EXPECT_NEAR(d.log_det, best - 6 * std::log(count), 1e-6);
  }
}

TEST(Design, IOptimalHasTheLowestMeanVarianceOfTheTwo) {
  const auto g = GridCandidates(PaperRanges(), 3);
  const auto d = DesignPowerLaw(g, 12, Criterion::kD);
  const auto i = DesignPowerLaw(g, 12, Criterion::kI);
  // The mean sd factor is not the I criterion itself (mean of sqrt), so compare loosely.
  EXPECT_LE(i.mean_sd_factor, d.mean_sd_factor * 1.02);
  EXPECT_GE(d.log_det, i.log_det - 1e-9);
}

TEST(Design, BadRequestsAreNamed) {
  EXPECT_THROW(DesignPowerLaw({}, 6, Criterion::kD), InputError);
  const auto g = GridCandidates(PaperRanges(), 2);
  EXPECT_THROW(DesignPowerLaw(g, 5, Criterion::kD), InputError);
  EXPECT_THROW(DesignPowerLaw(g, 33, Criterion::kD), InputError);
  InputRanges r = PaperRanges();
  std::swap(r.lo[2], r.hi[2]);
  try {
    r.Validate({"--a", "--b", "--pitch-mm-range", "--d", "--e"});
    FAIL() << "reversed range accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--pitch-mm-range 16..6: reversed"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(ParseCriterion("a"), InputError);
}

// Standardized log inputs (each input: mean 0, sd 1 over `all`), rows = screws.
Eigen::MatrixXd LogUnits(const std::vector<ProcessInputs>& all) {
  Eigen::MatrixXd u(all.size(), 5);
  for (std::size_t c = 0; c < all.size(); ++c)
    for (int j = 0; j < 5; ++j) u(c, j) = std::log(all[c].ToArray()[j]);
  for (int j = 0; j < 5; ++j) {
    const double m = u.col(j).mean();
    u.col(j) = (u.col(j).array() - m) / std::sqrt((u.col(j).array() - m).square().mean());
  }
  return u;
}

double Nearest(const Eigen::MatrixXd& u, int c, const std::vector<int>& from) {
  double d = 1e300;
  for (int i : from) d = std::min(d, (u.row(c) - u.row(i)).norm());
  return d;
}

std::vector<ProcessInputs> RandomList(std::mt19937& rng, int n) {
  std::uniform_real_distribution<double> u(0, 1);
  std::vector<ProcessInputs> cands;
  for (int i = 0; i < n; ++i)
    cands.push_back(ProcessInputs::FromArray(
        {60 + 5 * u(rng), 50 + 50 * u(rng), 6 + 10 * u(rng), 3 + 7 * u(rng), 150 + 60 * u(rng)}));
  return cands;
}

// The first `optimal` picks of a design `d` over `cands` (as candidate indices), checked to be the
// D-optimal design of their count.
std::vector<int> FirstPicksAreDOptimal(const std::vector<ProcessInputs>& cands,
                                       const PowerLawDesign& d, int optimal) {
  std::vector<int> before;
  for (int i = 0; i < optimal; ++i) before.push_back(d.picks[i].candidate);
  std::vector<int> opt;
  for (const auto& p : DesignPowerLaw(cands, optimal, Criterion::kD).picks)
    opt.push_back(p.candidate);
  EXPECT_EQ(std::set<int>(before.begin(), before.end()), std::set<int>(opt.begin(), opt.end()));
  return before;
}

TEST(Design, SpaceFillingPicksAreMaximinAfterTheOptimalOnes) {
  std::mt19937 rng(11);
  for (int t = 0; t < 10; ++t) {
    const auto cands = RandomList(rng, 80);
    const Eigen::MatrixXd u = LogUnits(cands);
    const auto d = DesignPowerLaw(cands, 9, Criterion::kD, 3);
    ASSERT_EQ(d.picks.size(), 9u);
    std::vector<int> before = FirstPicksAreDOptimal(cands, d, 6);
    // Each later pick is the candidate farthest from the picks before it (brute force).
    for (int i = 6; i < 9; ++i) {
      const int c = d.picks[i].candidate;
      const double mine = Nearest(u, c, before);
      for (int o = 0; o < static_cast<int>(cands.size()); ++o) {
        if (std::find(before.begin(), before.end(), o) != before.end()) continue;
        EXPECT_GE(mine, Nearest(u, o, before) - 1e-9) << "pick " << i << " candidate " << o;
      }
      EXPECT_EQ(d.picks[i].why.rfind("space filling", 0), 0u) << d.picks[i].why;
      before.push_back(c);
    }
    EXPECT_EQ(std::set<int>(before.begin(), before.end()).size(), 9u);
    // The reported maximin distance is the smallest pair distance of the design.
    double pair = 1e300;
    for (int i = 0; i < 9; ++i)
      for (int j = 0; j < i; ++j) pair = std::min(pair, (u.row(before[i]) - u.row(before[j])).norm());
    EXPECT_NEAR(d.min_distance, pair, 1e-9);
  }
}

TEST(Design, SpaceFillingCountsAreChecked) {
  const auto g = GridCandidates(PaperRanges(), 3);
  EXPECT_NO_THROW(DesignPowerLaw(g, 8, Criterion::kD, 2));
  EXPECT_THROW(DesignPowerLaw(g, 8, Criterion::kD, 3), InputError);  // 5 < 6 coefficients
  EXPECT_THROW(DesignPowerLaw(g, 8, Criterion::kD, -1), InputError);
}

// A GP on 12 rows of a smooth function of 2 inputs.
gp::Gp SmallGp() {
  Eigen::MatrixXd x(2, 12);
  Eigen::VectorXd y(12);
  for (int i = 0; i < 12; ++i) {
    x(0, i) = std::sin(1.3 * i), x(1, i) = std::cos(0.7 * i * i);
    y(i) = std::sin(2 * x(0, i)) + x(1, i) * x(1, i) + 0.01 * std::cos(17.0 * i);
  }
  gp::GpOptions o;
  o.mean = gp::Mean::kLinear;
  return gp::FitGp(x, y, o);
}

TEST(Design, PosteriorCovarianceMatchesPredictionAndRefit) {
  gp::Gp g = SmallGp();
  Eigen::MatrixXd q(2, 5);
  q << 0.1, -0.5, 0.9, 0.3, -0.2, 0.4, 0.8, -0.7, 0.0, 0.5;
  const Eigen::MatrixXd c = gp::PosteriorCovariance(g, q);
  const gp::GpPrediction p = gp::PredictGp(g, q);
  EXPECT_LT((c.diagonal() - p.latent_variance).cwiseAbs().maxCoeff(), 1e-10);
  EXPECT_LT((c - c.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  // Measuring q_2 (noise: the fitted noise): the rank-one update of design.h equals the GP with
  // that row appended at the same hyperparameters.
  const double scale2 = g.target_scale * g.target_scale;
  const double s2 = g.SigmaN2() * scale2;
  const Eigen::MatrixXd updated = c - c.col(2) * c.row(2) / (c(2, 2) + s2);
  gp::Gp h = g;
  h.z.conservativeResize(Eigen::NoChange, h.z.cols() + 1);
  h.z.col(h.z.cols() - 1) =
      g.input_scale.cwiseInverse().asDiagonal() * (q.col(2) - g.input_shift);
  h.u.conservativeResize(h.u.size() + 1);
  h.u(h.u.size() - 1) = 0.3;
  h.Factorize();
  EXPECT_LT((gp::PosteriorCovariance(h, q) - updated).cwiseAbs().maxCoeff(), 1e-9 * scale2);
}

TEST(Design, LinearCovarianceMatchesPrediction) {
  Eigen::MatrixXd x(2, 10);
  Eigen::VectorXd y(10);
  for (int i = 0; i < 10; ++i) x(0, i) = i, x(1, i) = i * i % 7, y(i) = 1 + x(0, i) + std::sin(i);
  const family::LinearModel m = family::FitLinear(x, y);
  const Eigen::MatrixXd c = family::LatentCovariance(m, x.leftCols(4));
  const auto p = family::PredictLinear(m, x.leftCols(4));
  EXPECT_LT((c.diagonal() - p.latent_variance).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Design, NextScrewsLowerTheVarianceAndStopRuleDecides) {
  const ProcessTable t = ReadProcessTable(WHIRL_SOURCE_DIR "/datasets/whirling_train.csv", true);
  workpiece::TrainOptions o;
  const auto model = workpiece::TrainWorkpieceModel(t, o, "whirling_train.csv");
  const auto cands = GridCandidates(PaperRanges(), 2);
  SpaceFilling measured;  // the default rule (switch) judges the measured screws and targets
  measured.measured = t.inputs;
  measured.measured_targets = t.targets;
  const NextDesign d = DesignNext(model, cands, 4, {}, {}, measured);
  ASSERT_EQ(d.picks.size(), 4u);
  std::set<int> seen;
  for (const auto& p : d.picks) {
    EXPECT_TRUE(seen.insert(p.candidate).second);
    for (int k = 0; k < 2; ++k) EXPECT_LE(p.sd_after[k], p.sd_now[k] + 1e-12);
  }
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT(d.rms_sd_after[k], d.rms_sd_now[k]);
    EXPECT_LE(d.rms_sd_floor[k], d.rms_sd_after[k] + 1e-12);
  }
  StopRule loose, tight, middle;
  loose.tolerance = {1e4, 1e4};
  tight.tolerance = {d.rms_sd_floor[0] / 2, 0};
  middle.tolerance = {(d.rms_sd_now[0] + d.rms_sd_floor[0]) / 2, 0};
  EXPECT_EQ(DesignNext(model, cands, 1, loose, {}, measured).stop, "enough");
  EXPECT_EQ(DesignNext(model, cands, 1, tight, {}, measured).stop, "floor");
  const NextDesign m = DesignNext(model, cands, 1, middle, {}, measured);
  EXPECT_EQ(m.stop, "continue");
  EXPECT_GE(m.screws_to_tolerance, 1);
}

TEST(Design, NextSpaceFillingPicksKeepAwayFromTheMeasured) {
  const ProcessTable t = ReadProcessTable(WHIRL_SOURCE_DIR "/datasets/whirling_train.csv", true);
  workpiece::TrainOptions o;
  const auto model = workpiece::TrainWorkpieceModel(t, o, "whirling_train.csv");
  const auto cands = GridCandidates(PaperRanges(), 3);
  SpaceFilling fill;
  fill.screws = 2;
  fill.measured = t.inputs;
  fill.measured_targets = t.targets;
  const NextDesign d = DesignNext(model, cands, 3, {}, {}, fill);
  SpaceFilling measured;
  measured.measured = t.inputs;
  measured.measured_targets = t.targets;
  const NextDesign plain = DesignNext(model, cands, 1, {}, {}, measured);
  ASSERT_EQ(d.picks.size(), 3u);
  EXPECT_EQ(d.picks[0].candidate, plain.picks[0].candidate);  // the variance pick comes first
  std::vector<ProcessInputs> all = cands;
  all.insert(all.end(), t.inputs.begin(), t.inputs.end());
  const Eigen::MatrixXd u = LogUnits(all);
  std::vector<int> near;
  for (std::size_t i = 0; i < t.inputs.size(); ++i) near.push_back(int(cands.size() + i));
  near.push_back(d.picks[0].candidate);
  for (int i = 1; i < 3; ++i) {
    const int c = d.picks[i].candidate;
    const double mine = Nearest(u, c, near);
    for (int other = 0; other < static_cast<int>(cands.size()); ++other) {
      if (std::find(near.begin(), near.end(), other) != near.end()) continue;
      EXPECT_GE(mine, Nearest(u, other, near) - 1e-9) << "pick " << i << " vs " << other;
    }
    for (int k = 0; k < 2; ++k) EXPECT_LE(d.picks[i].sd_after[k], d.picks[i].sd_now[k] + 1e-12);
    near.push_back(c);
  }
  SpaceFilling none;
  none.screws = 1;
  EXPECT_THROW(DesignNext(model, cands, 2, {}, {}, none), InputError);  // no --measured
  fill.screws = 4;
  EXPECT_THROW(DesignNext(model, cands, 3, {}, {}, fill), InputError);  // more than --count
}

// The mean posterior variance over `cands` of the power-GP rule's GP (design.h, NextRule), built
// here from scratch and refitted with the rows `measured` (standardized log inputs u, rows).
double PowerGpMeanVariance(const Eigen::MatrixXd& u, int n, const std::vector<int>& measured,
                           const NextRule& rule) {
  gp::Gp g;
  g.kernel = gp::Kernel::kMatern52;
  g.mean = gp::Mean::kLinear;
  const int d = static_cast<int>(u.cols());
  g.input_shift = Eigen::VectorXd::Zero(d);
  g.input_scale = Eigen::VectorXd::Ones(d);
  g.theta = Eigen::VectorXd::Zero(d + 2);
  g.theta.head(d).setConstant(std::log(rule.length_scale));
  g.theta(d) = std::log(rule.departure_ratio);
  g.z.resize(d, static_cast<Eigen::Index>(measured.size()));
  for (std::size_t i = 0; i < measured.size(); ++i) g.z.col(long(i)) = u.row(measured[i]).transpose();
  g.u = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(measured.size()));
  g.Factorize();
  return gp::PosteriorCovariance(g, u.topRows(n).transpose()).diagonal().mean();
}

workpiece::WorkpieceModel TrainedModel() {
  const ProcessTable t = ReadProcessTable(WHIRL_SOURCE_DIR "/datasets/whirling_train.csv", true);
  workpiece::TrainOptions o;
  return workpiece::TrainWorkpieceModel(t, o, "whirling_train.csv");
}

TEST(Design, PowerGpPicksTheLargestVarianceReductionByRefit) {
  const auto model = TrainedModel();
  std::mt19937 rng(5);
  for (int t = 0; t < 5; ++t) {
    const auto cands = RandomList(rng, 40);
    const auto measured = RandomList(rng, 9);
    SpaceFilling fill;
    fill.measured = measured;
    NextRule rule;
    rule.model = NextRule::Model::kPowerGp;
    const NextDesign d = DesignNext(model, cands, 3, {}, {}, fill, rule);
    ASSERT_EQ(d.picks.size(), 3u);
    // Deterministic, distinct, inside the list.
    const NextDesign again = DesignNext(model, cands, 3, {}, {}, fill, rule);
    std::set<int> seen;
    for (std::size_t i = 0; i < 3; ++i) {
      EXPECT_EQ(d.picks[i].candidate, again.picks[i].candidate);
      EXPECT_GE(d.picks[i].candidate, 0);
      EXPECT_LT(d.picks[i].candidate, 40);
      EXPECT_TRUE(seen.insert(d.picks[i].candidate).second);
      EXPECT_NE(d.picks[i].why.find("smooth departure"), std::string::npos) << d.picks[i].why;
    }
    // Each pick is the candidate whose measurement, refitted from scratch, leaves the lowest
    // mean variance over the list given the measured screws and the picks before it.
    std::vector<ProcessInputs> all = cands;
    all.insert(all.end(), measured.begin(), measured.end());
    const Eigen::MatrixXd u = LogUnits(all);
    std::vector<int> rows;
    for (int i = 0; i < 9; ++i) rows.push_back(40 + i);
    for (const auto& p : d.picks) {
      std::vector<int> with = rows;
      with.push_back(p.candidate);
      const double mine = PowerGpMeanVariance(u, 40, with, rule);
      for (int c = 0; c < 40; ++c) {
        if (std::find(rows.begin(), rows.end(), c) != rows.end()) continue;
        with.back() = c;
        EXPECT_LE(mine, PowerGpMeanVariance(u, 40, with, rule) + 1e-9) << "candidate " << c;
      }
      rows.push_back(p.candidate);
    }
  }
}

TEST(Design, PowerGpLooksInsideTheMeasuredCorners) {
  // Two inputs vary over a 3 x 3 grid in log steps; the four corners are measured: the power
  // law is determined there, a departure is least known at the centre, which is also nearest
  // to every other candidate, so the first pick is the centre (by symmetry, hand-checkable).
  const auto model = TrainedModel();
  std::vector<ProcessInputs> grid;
  for (double dia : {50.0, std::sqrt(50.0 * 100.0), 100.0})
    for (double pitch : {6.0, std::sqrt(6.0 * 16.0), 16.0})
      grid.push_back(ProcessInputs::FromArray({62, dia, pitch, 5, 180}));
  SpaceFilling fill;
  std::vector<ProcessInputs> cands;
  for (int i : {0, 2, 6, 8}) fill.measured.push_back(grid[i]);
  for (int i : {1, 3, 4, 5, 7}) cands.push_back(grid[i]);  // the centre is cands[2]
  NextRule power_gp;
  power_gp.model = NextRule::Model::kPowerGp;
  const NextDesign d = DesignNext(model, cands, 2, {}, {}, fill, power_gp);
  EXPECT_EQ(d.picks[0].candidate, 2);
  // The chosen family's rule (the power law on this table) has its least variance at the
  // centre and picks an edge.
  NextRule chosen;
  chosen.model = NextRule::Model::kChosen;
  EXPECT_NE(DesignNext(model, cands, 1, {}, {}, fill, chosen).picks[0].candidate, 2);
}

// --variance auto follows cross-validation per output: a model whose outputs are both linear
// (the power law) picks as power-gp, one whose outputs are both GPs as the chosen family's.
std::vector<int> PickedBy(const workpiece::WorkpieceModel& model,
                          const std::vector<ProcessInputs>& cands, const SpaceFilling& fill,
                          NextRule::Model m) {
  NextRule rule;
  rule.model = m;
  std::vector<int> out;
  for (const auto& p : DesignNext(model, cands, 4, {}, {}, fill, rule).picks)
    out.push_back(p.candidate);
  return out;
}

TEST(Design, AutoVarianceFollowsTheChosenFamilyPerOutput) {
  const ProcessTable t = ReadProcessTable(WHIRL_SOURCE_DIR "/datasets/whirling_train.csv", true);
  std::mt19937 rng(21);
  const auto cands = RandomList(rng, 60);
  SpaceFilling fill;
  fill.measured = t.inputs;
  using M = NextRule::Model;
  for (const auto flag : {workpiece::FamilyFlag::kLinear, workpiece::FamilyFlag::kGaussianProcess}) {
    workpiece::TrainOptions o;
    o.family = flag;
    o.transform = workpiece::TransformFlag::kLog;
    const auto model = workpiece::TrainWorkpieceModel(t, o, "whirling_train.csv");
    const auto power_gp = PickedBy(model, cands, fill, M::kPowerGp);
    const auto chosen = PickedBy(model, cands, fill, M::kChosen);
    ASSERT_NE(power_gp, chosen);  // else the check below could not tell the rules apart
    EXPECT_EQ(PickedBy(model, cands, fill, M::kAuto),
              flag == workpiece::FamilyFlag::kLinear ? power_gp : chosen);
  }
  EXPECT_EQ(ParseNextModel("auto"), M::kAuto);
  EXPECT_EQ(ToString(M::kAuto), "auto");
}

TEST(Design, InsidePicksReduceThePowerGpVarianceMostAfterTheOptimalOnes) {
  std::mt19937 rng(21);
  for (int t = 0; t < 5; ++t) {
    const auto cands = RandomList(rng, 60);
    const auto d = DesignPowerLaw(cands, 8, Criterion::kD, 0, 2);
    const auto optimal = DesignPowerLaw(cands, 6, Criterion::kD);
    ASSERT_EQ(d.picks.size(), 8u);
    std::vector<int> before, opt;
    for (int i = 0; i < 6; ++i) before.push_back(d.picks[i].candidate);
    for (const auto& p : optimal.picks) opt.push_back(p.candidate);
    EXPECT_EQ(std::set<int>(before.begin(), before.end()), std::set<int>(opt.begin(), opt.end()));
    const Eigen::MatrixXd u = LogUnits(cands);
    for (int i = 6; i < 8; ++i) {
      std::vector<int> with = before;
      with.push_back(d.picks[i].candidate);
      const double mine = PowerGpMeanVariance(u, 60, with, NextRule{});
      for (int c = 0; c < 60; ++c) {
        if (std::find(before.begin(), before.end(), c) != before.end()) continue;
        with.back() = c;
        EXPECT_LE(mine, PowerGpMeanVariance(u, 60, with, NextRule{}) + 1e-9) << "candidate " << c;
      }
      EXPECT_EQ(d.picks[i].why.rfind("inside the range", 0), 0u) << d.picks[i].why;
      before.push_back(d.picks[i].candidate);
    }
    EXPECT_EQ(std::set<int>(before.begin(), before.end()).size(), 8u);
  }
  EXPECT_THROW(DesignPowerLaw(RandomList(rng, 30), 8, Criterion::kD, 0, 3), InputError);
  EXPECT_THROW(DesignPowerLaw(RandomList(rng, 30), 8, Criterion::kD, 0, -2), InputError);
  // kInsideAuto (whirl design's default): up to kDefaultInside, within the room the count leaves.
  const auto list = RandomList(rng, 30);
  EXPECT_EQ(DesignPowerLaw(list, 8, Criterion::kD, 0, kInsideAuto).inside, 2);
  EXPECT_EQ(DesignPowerLaw(list, 12, Criterion::kD, 0, kInsideAuto).inside, 2);
  EXPECT_EQ(DesignPowerLaw(list, 7, Criterion::kD, 0, kInsideAuto).inside, 1);
  EXPECT_EQ(DesignPowerLaw(list, 6, Criterion::kD, 0, kInsideAuto).inside, 0);
  EXPECT_EQ(DesignPowerLaw(list, 8, Criterion::kD, 1, kInsideAuto).inside, 1);
}

// --variance switch (design.h, NextRule::kSwitch). The leave-one-out residual of screw i, refitted
// from scratch on the other screws: the power law by least squares, the power-GP by its
// posterior mean (universal kriging, the same hyperparameters).
double RefitResidual(const Eigen::MatrixXd& z, const Eigen::VectorXd& y, int i, bool power_gp,
                     const NextRule& rule) {
  const int m = static_cast<int>(z.rows()), d = static_cast<int>(z.cols());
  Eigen::MatrixXd zr(m - 1, d);
  Eigen::VectorXd yr(m - 1);
  for (int r = 0, q = 0; r < m; ++r)
    if (r != i) zr.row(q) = z.row(r), yr(q++) = y(r);
  if (!power_gp) {
    Eigen::MatrixXd h(m - 1, d + 1);
    h << Eigen::VectorXd::Ones(m - 1), zr;
    const Eigen::VectorXd b = h.colPivHouseholderQr().solve(yr);
    return y(i) - (b(0) + z.row(i).dot(b.tail(d)));
  }
  gp::Gp g;
  g.kernel = gp::Kernel::kMatern52;
  g.mean = gp::Mean::kLinear;
  g.input_shift = Eigen::VectorXd::Zero(d);
  g.input_scale = Eigen::VectorXd::Ones(d);
  g.theta = Eigen::VectorXd::Zero(d + 2);
  g.theta.head(d).setConstant(std::log(rule.length_scale));
  g.theta(d) = std::log(rule.departure_ratio);
  g.z = zr.transpose();
  g.u = yr;
  g.Factorize();
  return y(i) - gp::PredictGp(g, z.row(i).transpose()).mean(0);
}

// ln y of a power law in the standardized log inputs z, plus a smooth bump of size `bump`
// around the centre and noise of sd `noise`.
Eigen::VectorXd LogTargets(const Eigen::MatrixXd& z, double bump, double noise, std::mt19937& rng) {
  std::normal_distribution<double> e(0, 1);
  Eigen::VectorXd y(z.rows());
  for (Eigen::Index i = 0; i < z.rows(); ++i)
    y(i) = 3 + 0.5 * z(i, 0) - 0.3 * z(i, 1) + 0.2 * z(i, 2) +
           bump * std::exp(-z.row(i).squaredNorm() / 2) + noise * e(rng);
  return y;
}

TEST(Design, SwitchLackOfFitMatchesLeaveOneOutRefits) {
  std::mt19937 rng(31);
  std::normal_distribution<double> e(0, 1);
  const NextRule rule;
  for (int t = 0; t < 4; ++t) {
    Eigen::MatrixXd z(12 + 4 * t, 5);
    for (Eigen::Index i = 0; i < z.size(); ++i) z(i) = e(rng);
    const Eigen::VectorXd y = LogTargets(z, 0.3 * t, 0.05, rng);
    double s0 = 0, s1 = 0;
    for (int i = 0; i < z.rows(); ++i) {
      s0 += std::pow(RefitResidual(z, y, i, false, rule), 2);
      s1 += std::pow(RefitResidual(z, y, i, true, rule), 2);
    }
    const LackOfFit f = PowerLawLackOfFit(z, y, rule);
    EXPECT_EQ(f.rows, z.rows());
    EXPECT_NEAR(f.power_law_rmse, std::sqrt(s0 / z.rows()), 1e-6 * f.power_law_rmse);
    // The closed form carries gp::Gp's noise floor (1e-6 of the scatter's variance).
    EXPECT_NEAR(f.power_gp_rmse, std::sqrt(s1 / z.rows()), 1e-5 * f.power_gp_rmse);
    EXPECT_NEAR(f.ratio, f.power_law_rmse / f.power_gp_rmse, 1e-12);
  }
}

TEST(Design, SwitchLackOfFitSeesTheDepartureNotTheNoise) {
  std::mt19937 rng(32);
  std::normal_distribution<double> e(0, 1);
  // A power law with scatter: the departure mostly follows noise and predicts worse (the ratio
  // scatters around 0.9 at 30 screws, above 1 about one time in five); a bump of 1 (a factor e
  // at the centre) with 3 % scatter: the power law misses it every time.
  int above_null = 0;
  for (int t = 0; t < 20; ++t) {
    Eigen::MatrixXd z(30, 5);
    for (Eigen::Index i = 0; i < z.size(); ++i) z(i) = e(rng);
    above_null += PowerLawLackOfFit(z, LogTargets(z, 0, t % 2 ? 0.03 : 0.15, rng), {}).ratio > 1;
    EXPECT_GT(PowerLawLackOfFit(z, LogTargets(z, 1.0, 0.03, rng), {}).ratio, 1.25) << t;
  }
  EXPECT_LE(above_null, 8);
  // Six screws, five inputs: every leverage is 1, nothing is left out: no evidence.
  Eigen::MatrixXd z(6, 5);
  for (Eigen::Index i = 0; i < z.size(); ++i) z(i) = e(rng);
  const LackOfFit none = PowerLawLackOfFit(z, LogTargets(z, 1.0, 0.03, rng), {});
  EXPECT_EQ(none.rows, 0);
  EXPECT_EQ(none.ratio, 0.0);
  EXPECT_THROW(PowerLawLackOfFit(z.topRows(5), Eigen::VectorXd::Ones(5), {}), InputError);
}

// Targets of `measured` with ln y = the power law of LogTargets (+ bump) on their own
// standardized log inputs, both outputs alike (levels of the simulator's: 20 um, 100 s).
std::vector<Features> MeasuredTargets(const std::vector<ProcessInputs>& measured, double bump,
                                      std::mt19937& rng) {
  const Eigen::MatrixXd z = LogUnits(measured);
  const Eigen::VectorXd y = LogTargets(z, bump, 0.03, rng);
  std::vector<Features> out;
  for (Eigen::Index i = 0; i < z.rows(); ++i)
    out.push_back(Features::FromArray({std::exp(y(i) - 3) * 20, std::exp(y(i) - 3) * 100}));
  return out;
}

TEST(Design, SwitchUsesTheChosenVarianceWhileThePowerLawFits) {
  const auto model = TrainedModel();  // the power law on both outputs
  std::mt19937 rng(33);
  using M = NextRule::Model;
  int fits = 0, departs = 0;
  for (int t = 0; t < 6; ++t) {
    const auto cands = RandomList(rng, 50);
    SpaceFilling fill;
    fill.measured = RandomList(rng, 30);
    const auto power_gp = PickedBy(model, cands, fill, M::kPowerGp);
    const auto chosen = PickedBy(model, cands, fill, M::kChosen);
    ASSERT_NE(power_gp, chosen);  // else the checks below could not tell the rules apart
    fill.measured_targets = MeasuredTargets(fill.measured, t % 2 ? 1.0 : 0.0, rng);
    NextRule rule;
    rule.model = M::kSwitch;
    const NextDesign d = DesignNext(model, cands, 4, {}, {}, fill, rule);
    std::vector<int> picked;
    for (const auto& p : d.picks) picked.push_back(p.candidate);
    // Both outputs share ln y up to a constant: one ratio, one side of the threshold; it is
    // the lack of fit on the measured screws' rows of the log inputs standardized over list
    // and measured screws.
    std::vector<ProcessInputs> all = cands;
    all.insert(all.end(), fill.measured.begin(), fill.measured.end());
    Eigen::VectorXd ln_y(30);
    for (int i = 0; i < 30; ++i) ln_y(i) = std::log(fill.measured_targets[i].ToArray()[0]);
    const double ratio = PowerLawLackOfFit(LogUnits(all).bottomRows(30), ln_y, rule).ratio;
    EXPECT_NEAR(d.lack_of_fit_ratio[0], ratio, 1e-9 * ratio);
    EXPECT_NEAR(d.lack_of_fit_ratio[1], ratio, 1e-9 * ratio);
    const bool departure = ratio > rule.switch_ratio;
    EXPECT_EQ(picked, departure ? power_gp : chosen) << "ratio " << ratio;
    if (t % 2) {
      EXPECT_TRUE(departure) << "a bump of 1, ratio " << ratio;
    }
    fits += !departure, departs += departure;
    EXPECT_NE(d.picks[0].why.find(departure ? "depart from the power law" : "power law fits"),
              std::string::npos) << d.picks[0].why;
    // The threshold decides: far above every ratio, the chosen family's; far below, power-gp.
    rule.switch_ratio = 1e9;
    std::vector<int> high, low;
    for (const auto& p : DesignNext(model, cands, 4, {}, {}, fill, rule).picks)
      high.push_back(p.candidate);
    rule.switch_ratio = 1e-9;
    for (const auto& p : DesignNext(model, cands, 4, {}, {}, fill, rule).picks)
      low.push_back(p.candidate);
    EXPECT_EQ(high, chosen);
    EXPECT_EQ(low, power_gp);
  }
  EXPECT_GE(fits, 1);  // both sides seen
  EXPECT_GE(departs, 3);
}

TEST(Design, SwitchNeedsTheMeasuredTargets) {
  const auto model = TrainedModel();
  std::mt19937 rng(34);
  const auto cands = RandomList(rng, 20);
  SpaceFilling fill;
  fill.measured = RandomList(rng, 10);
  NextRule rule;
  rule.model = NextRule::Model::kSwitch;
  try {
    DesignNext(model, cands, 1, {}, {}, fill, rule);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("targets"), std::string::npos) << e.what();
  }
  fill.measured_targets = MeasuredTargets(fill.measured, 0, rng);
  EXPECT_NO_THROW(DesignNext(model, cands, 1, {}, {}, fill, rule));
  fill.measured_targets[3] = Features::FromArray({0.0, 100.0});
  EXPECT_THROW(DesignNext(model, cands, 1, {}, {}, fill, rule), InputError);
  rule.switch_ratio = 0;
  fill.measured_targets = MeasuredTargets(fill.measured, 0, rng);
  EXPECT_THROW(DesignNext(model, cands, 1, {}, {}, fill, rule), InputError);
  EXPECT_EQ(ParseNextModel("switch"), NextRule::Model::kSwitch);
  EXPECT_EQ(ToString(NextRule::Model::kSwitch), "switch");
  EXPECT_EQ(ToString(NextRule::Model::kAuto), "auto");
}

TEST(Design, PowerGpNeedsEnoughMeasuredScrews) {
  const auto model = TrainedModel();
  std::mt19937 rng(8);
  const auto cands = RandomList(rng, 20);
  NextRule power_gp;
  power_gp.model = NextRule::Model::kPowerGp;
  for (const NextRule& rule : {power_gp, NextRule{}}) {  // NextRule{}: the default, switch
    SpaceFilling fill;
    EXPECT_THROW(DesignNext(model, cands, 1, {}, {}, fill, rule), InputError);  // none measured
    fill.measured = RandomList(rng, 5);  // 5 inputs: 6 needed (the power law's coefficients)
    fill.measured_targets = MeasuredTargets(fill.measured, 0, rng);
    try {
      DesignNext(model, cands, 1, {}, {}, fill, rule);
      ADD_FAILURE() << "expected an InputError";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("at least 6 measured screws"), std::string::npos)
          << e.what();
    }
    fill.measured = RandomList(rng, 6);
    fill.measured_targets = MeasuredTargets(fill.measured, 0, rng);
    EXPECT_NO_THROW(DesignNext(model, cands, 1, {}, {}, fill, rule));
  }
  EXPECT_EQ(NextRule{}.model, NextRule::Model::kSwitch);
  EXPECT_EQ(ParseNextModel("sum"), NextRule::Model::kSum);
  EXPECT_THROW(ParseNextModel("gp"), InputError);
}

// The mean over the list (rows 0..n-1 of u) of each row's distance to its nearest row of `from`.
double MeanNearest(const Eigen::MatrixXd& u, int n, const std::vector<int>& from) {
  double s = 0;
  for (int i = 0; i < n; ++i) s += Nearest(u, i, from);
  return s / n;
}

// Each coverage pick lowers the list's mean distance to its nearest screw the most (brute force
// over the unpicked candidates), and is not the maximin pick (which goes to the edges).
void ExpectCoveragePicks(const Eigen::MatrixXd& u, int n, const std::vector<Pick>& picks,
                         std::size_t first, std::vector<int> near, int* differs) {
  for (std::size_t i = first; i < picks.size(); ++i) {
    const int c = picks[i].candidate;
    std::vector<int> with = near;
    with.push_back(c);
    const double mine = MeanNearest(u, n, with);
    int farthest = -1;
    double far = -1;
    for (int o = 0; o < n; ++o) {
      if (std::find(near.begin(), near.end(), o) != near.end()) continue;
      with.back() = o;
      EXPECT_LE(mine, MeanNearest(u, n, with) + 1e-12) << "pick " << i << " candidate " << o;
      if (Nearest(u, o, near) > far) far = Nearest(u, o, near), farthest = o;
    }
    *differs += farthest != c;
    EXPECT_EQ(picks[i].why.rfind("coverage", 0), 0u) << picks[i].why;
    EXPECT_LT(mine, MeanNearest(u, n, near));
    near.push_back(c);
  }
}

TEST(Design, CoveragePicksLowerTheMeanDistanceToTheNearestScrewMost) {
  std::mt19937 rng(41);
  int differs = 0;
  for (int t = 0; t < 6; ++t) {
    const auto cands = RandomList(rng, 70);
    const Eigen::MatrixXd u = LogUnits(cands);
    const auto d = DesignPowerLaw(cands, 9, Criterion::kD, 3, 0, {}, FillRule::kCoverage);
    ASSERT_EQ(d.picks.size(), 9u);
    const std::vector<int> before = FirstPicksAreDOptimal(cands, d, 6);
    ExpectCoveragePicks(u, 70, d.picks, 6, before, &differs);
  }
  EXPECT_GE(differs, 3);  // coverage is not maximin under another name
}

TEST(Design, NextCoveragePicksKeepNearTheListAwayFromTheMeasured) {
  const auto model = TrainedModel();
  std::mt19937 rng(42);
  int differs = 0;
  for (int t = 0; t < 4; ++t) {
    const auto cands = RandomList(rng, 60);
    SpaceFilling fill;
    fill.screws = 2;
    fill.rule = FillRule::kCoverage;
    fill.measured = RandomList(rng, 12);
    fill.measured_targets = MeasuredTargets(fill.measured, 0.0, rng);
    const NextDesign d = DesignNext(model, cands, 3, {}, {}, fill);
    ASSERT_EQ(d.picks.size(), 3u);
    EXPECT_EQ(d.space_filling, 2);
    std::vector<ProcessInputs> all = cands;
    all.insert(all.end(), fill.measured.begin(), fill.measured.end());
    std::vector<int> near;
    for (int i = 0; i < 12; ++i) near.push_back(60 + i);
    near.push_back(d.picks[0].candidate);
    ExpectCoveragePicks(LogUnits(all), 60, d.picks, 1, near, &differs);
    for (const auto& p : d.picks)
      for (int k = 0; k < 2; ++k) EXPECT_LE(p.sd_after[k], p.sd_now[k] + 1e-12);
  }
  EXPECT_GE(differs, 2);
}

TEST(Design, SpaceFillingWhenDepartureFollowsTheSwitch) {
  const auto model = TrainedModel();
  std::mt19937 rng(43);
  int with = 0, without = 0;
  for (int t = 0; t < 4; ++t) {
    const auto cands = RandomList(rng, 50);
    SpaceFilling fill;
    fill.measured = RandomList(rng, 30);
    fill.measured_targets = MeasuredTargets(fill.measured, t % 2 ? 1.0 : 0.0, rng);
    const NextDesign plain = DesignNext(model, cands, 2, {}, {}, fill);
    fill.screws = 1;
    fill.rule = FillRule::kCoverage;
    const NextDesign always = DesignNext(model, cands, 2, {}, {}, fill);
    fill.when = SpaceFilling::When::kDeparture;
    const NextDesign d = DesignNext(model, cands, 2, {}, {}, fill);
    const bool departure = std::max(d.lack_of_fit_ratio[0], d.lack_of_fit_ratio[1]) >
                           NextRule{}.switch_ratio;
    EXPECT_EQ(d.space_filling, departure ? 1 : 0);
    EXPECT_EQ(always.space_filling, 1);
    const NextDesign& same = departure ? always : plain;
    for (int i = 0; i < 2; ++i) EXPECT_EQ(d.picks[i].candidate, same.picks[i].candidate);
    with += departure, without += !departure;
  }
  EXPECT_GE(with, 1);  // both sides seen
  EXPECT_GE(without, 1);
  SpaceFilling fill;
  fill.screws = 1;
  fill.when = SpaceFilling::When::kDeparture;
  fill.measured = RandomList(rng, 12);
  NextRule power_gp;
  power_gp.model = NextRule::Model::kPowerGp;
  EXPECT_THROW(DesignNext(model, RandomList(rng, 20), 2, {}, {}, fill, power_gp), InputError);
  EXPECT_EQ(ParseFillRule("coverage"), FillRule::kCoverage);
  EXPECT_EQ(ToString(ParseFillWhen("departure")), "departure");
  EXPECT_THROW(ParseFillRule("random"), InputError);
  EXPECT_THROW(ParseFillWhen("never"), InputError);
}

// ---- The design follows the default model: sd_scale, stacked outputs, network candidates ------

ProcessTable TrainTable() {
  return ReadProcessTable(WHIRL_SOURCE_DIR "/datasets/whirling_train.csv", true);
}

// The next-screws rule that follows the model's own choice per output.
NextRule ChosenRule() {
  NextRule rule;
  rule.model = NextRule::Model::kChosen;
  return rule;
}

// Space filling that counts the training table as measured.
SpaceFilling TrainFill() {
  SpaceFilling fill;
  fill.measured = TrainTable().inputs;
  return fill;
}

// A family model of the named candidates fitted on the training table: output k is models
// [of[k]] alone (weights empty), or the stack `weights[k]` where given; sd factors `scale`.
workpiece::WorkpieceModel HandChoice(const std::vector<std::string>& names,
                                     std::array<int, 2> of,
                                     std::array<std::vector<double>, 2> weights,
                                     std::array<double, 2> scale) {
  const ProcessTable t = TrainTable();
  family::Choice c;
  for (const auto& n : names)
    c.models.push_back(family::FitCandidate(t, family::ParseCandidate(n), family::FitOptions{}));
  c.model_of_output = of;
  c.chosen = of;
  c.weights = std::move(weights);
  c.sd_scale = scale;
  return workpiece::FromChoice(std::move(c), t, "whirling_train.csv");
}

std::vector<int> Candidates(const NextDesign& d) {
  std::vector<int> out;
  for (const auto& p : d.picks) out.push_back(p.candidate);
  return out;
}

TEST(Design, SdScaleScalesEverySdAndTheStopRuleNotThePicks) {
  std::mt19937 rng(71);
  const auto cands = RandomList(rng, 40);
  SpaceFilling fill;  // the default rule (switch) with the training table as measured screws
  const ProcessTable t = TrainTable();
  fill.measured = t.inputs;
  fill.measured_targets = t.targets;
  const auto plain = HandChoice({"linear/log", "gp-matern52-constant/identity"}, {0, 1}, {},
                                {1.0, 1.0});
  auto scaled = plain;
  scaled.choice.sd_scale = {0.5, 0.8};  // family::Choice::sd_scale of a calibrated choice
  const NextDesign a = DesignNext(plain, cands, 3, {}, {}, fill);
  const NextDesign b = DesignNext(scaled, cands, 3, {}, {}, fill);
  EXPECT_EQ(Candidates(a), Candidates(b));
  const std::array<double, 2> s = {0.5, 0.8};
  const auto predicted = workpiece::PredictBatch(scaled, cands);
  for (std::size_t i = 0; i < a.picks.size(); ++i)
    for (int k = 0; k < 2; ++k) {
      EXPECT_NEAR(b.picks[i].sd_now[k], s[k] * a.picks[i].sd_now[k], 1e-12 * a.picks[i].sd_now[k]);
      EXPECT_NEAR(b.picks[i].sd_after[k], s[k] * a.picks[i].sd_after[k],
                  1e-12 * a.picks[i].sd_after[k]);
      // The sd now is the one `whirl predict` gives (sd_scale included).
      EXPECT_NEAR(b.picks[i].sd_now[k], predicted[b.picks[i].candidate].stddev.ToArray()[k],
                  1e-9 * b.picks[i].sd_now[k]);
    }
  for (int k = 0; k < 2; ++k) {
    EXPECT_NEAR(b.rms_sd_now[k], s[k] * a.rms_sd_now[k], 1e-12 * a.rms_sd_now[k]);
    EXPECT_NEAR(b.rms_sd_after[k], s[k] * a.rms_sd_after[k], 1e-12 * a.rms_sd_after[k]);
    EXPECT_NEAR(b.rms_sd_floor[k], s[k] * a.rms_sd_floor[k], 1e-12 * a.rms_sd_floor[k]);
  }
  // A tolerance between the scaled and the unscaled RMS sd: enough for the scaled model only.
  StopRule between;
  between.tolerance = {0.7 * a.rms_sd_now[0], 0};
  ASSERT_LE(a.rms_sd_floor[0] * 0.5, between.tolerance[0]);
  EXPECT_EQ(DesignNext(scaled, cands, 1, between, {}, fill).stop, "enough");
  EXPECT_NE(DesignNext(plain, cands, 1, between, {}, fill).stop, "enough");
}

TEST(Design, StackedOutputsTakeTheModelsCombinedSd) {
  std::mt19937 rng(72);
  const auto cands = RandomList(rng, 30);
  const SpaceFilling fill = TrainFill();
  const NextRule chosen = ChosenRule();
  const std::vector<std::string> names = {"linear/log", "gp-matern52-constant/identity"};
  const auto stack = HandChoice(names, {1, 1}, {std::vector<double>{0.3, 0.7}, {0.6, 0.4}},
                                {0.8, 0.9});
  const NextDesign d = DesignNext(stack, cands, 3, {}, {}, fill, chosen);
  ASSERT_EQ(d.picks.size(), 3u);
  // By hand: sd = sd_scale (w_1 sd_1 + w_2 sd_2) with each candidate's own predictive sd.
  const auto p0 = family::PredictFamily(stack.choice.models[0], cands);
  const auto p1 = family::PredictFamily(stack.choice.models[1], cands);
  const std::array<std::array<double, 2>, 2> w = {{{0.3, 0.7}, {0.6, 0.4}}};
  const std::array<double, 2> s = {0.8, 0.9};
  for (const auto& p : d.picks)
    for (int k = 0; k < 2; ++k) {
      const double hand = s[k] * (w[k][0] * p0[p.candidate].stddev.ToArray()[k] +
                                  w[k][1] * p1[p.candidate].stddev.ToArray()[k]);
      EXPECT_NEAR(p.sd_now[k], hand, 1e-9 * hand);
      EXPECT_LE(p.sd_after[k], p.sd_now[k] + 1e-12);
    }
  for (int k = 0; k < 2; ++k) {
    EXPECT_LT(d.rms_sd_after[k], d.rms_sd_now[k]);
    EXPECT_LE(d.rms_sd_floor[k], d.rms_sd_after[k] + 1e-12);
  }
  // A stack whose weight is all on one candidate is that candidate (same picks, same sds).
  const auto whole = HandChoice(names, {0, 0}, {std::vector<double>{1.0, 0.0}, {1.0, 0.0}},
                                {0.8, 0.9});
  const auto alone = HandChoice(names, {0, 0}, {}, {0.8, 0.9});
  const NextDesign dw = DesignNext(whole, cands, 3, {}, {}, fill, chosen);
  const NextDesign da = DesignNext(alone, cands, 3, {}, {}, fill, chosen);
  EXPECT_EQ(Candidates(dw), Candidates(da));
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(dw.rms_sd_after[k], da.rms_sd_after[k], 1e-9);
}

TEST(Design, NetworkCandidatesTakeTheirLaplaceCovariance) {
  std::mt19937 rng(73);
  const auto cands = RandomList(rng, 30);
  const SpaceFilling fill = TrainFill();
  const NextRule chosen = ChosenRule();
  const auto net = HandChoice({"network-h2/identity"}, {0, 0}, {}, {1.0, 1.0});
  const NextDesign d = DesignNext(net, cands, 4, {}, {}, fill, chosen);
  ASSERT_EQ(d.picks.size(), 4u);
  // The covariance's diagonal plus the calibrated noise is nn's own predictive variance.
  const auto p = family::PredictFamily(net.choice.models[0], cands);
  std::set<int> seen;
  for (const auto& pick : d.picks) {
    EXPECT_TRUE(seen.insert(pick.candidate).second);
    for (int k = 0; k < 2; ++k) {
      const double own = p[pick.candidate].stddev.ToArray()[k];
      EXPECT_NEAR(pick.sd_now[k], own, 1e-9 * own);
      EXPECT_LE(pick.sd_after[k], pick.sd_now[k] + 1e-12);
    }
  }
  for (int k = 0; k < 2; ++k) EXPECT_LE(d.rms_sd_after[k], d.rms_sd_now[k]);
  // The first pick lowers the summed variance most: no other candidate measured alone does
  // better (the first pick of a greedy batch is the exact optimum of one screw).
  const NextDesign first = DesignNext(net, cands, 1, {}, {}, fill, chosen);
  EXPECT_EQ(first.picks[0].candidate, d.picks[0].candidate);
}

TEST(Design, ChoiceEvidenceSwitchesWhereTheModelLeftThePowerLaw) {
  std::mt19937 rng(74);
  const auto cands = RandomList(rng, 40);
  SpaceFilling fill;
  fill.measured = RandomList(rng, 20);
  fill.measured_targets = MeasuredTargets(fill.measured, 0, rng);  // a power law: no lack of fit
  NextRule lack, choice, power_gp;
  lack.switch_ratio = choice.switch_ratio = 1e9;  // the lack of fit never departs
  choice.evidence = NextRule::Evidence::kChoice;
  power_gp.model = NextRule::Model::kPowerGp;
  // Linear on raw columns for both outputs: the choice left the power law; power-gp's picks.
  const auto raw = HandChoice({"linear/identity"}, {0, 0}, {}, {1.0, 1.0});
  const NextDesign c = DesignNext(raw, cands, 3, {}, {}, fill, choice);
  EXPECT_TRUE(c.choice_departure[0] && c.choice_departure[1]);
  EXPECT_TRUE(c.departure[0] && c.departure[1]);
  EXPECT_EQ(Candidates(c), Candidates(DesignNext(raw, cands, 3, {}, {}, fill, power_gp)));
  EXPECT_NE(c.picks[0].why.find("choice left the power law"), std::string::npos) << c.picks[0].why;
  const NextDesign l = DesignNext(raw, cands, 3, {}, {}, fill, lack);
  EXPECT_FALSE(l.departure[0] || l.departure[1] || l.choice_departure[0]);
  // The power law on both outputs: the choice adds nothing.
  const auto power = HandChoice({"linear/log"}, {0, 0}, {}, {1.0, 1.0});
  const NextDesign pc = DesignNext(power, cands, 3, {}, {}, fill, choice);
  EXPECT_FALSE(pc.choice_departure[0] || pc.choice_departure[1]);
  EXPECT_EQ(Candidates(pc), Candidates(DesignNext(power, cands, 3, {}, {}, fill, lack)));
  // A stack with weight beyond the power law departs; the power law taking it whole does not.
  const std::vector<std::string> names = {"linear/log", "linear/identity"};
  const auto mixed = HandChoice(names, {0, 0}, {std::vector<double>{0.5, 0.5}, {1.0, 0.0}},
                                {1.0, 1.0});
  const NextDesign m = DesignNext(mixed, cands, 2, {}, {}, fill, choice);
  EXPECT_TRUE(m.choice_departure[0]);
  EXPECT_FALSE(m.choice_departure[1]);
  // Only with the switch; spellings.
  NextRule bad = choice;
  bad.model = NextRule::Model::kChosen;
  EXPECT_THROW(DesignNext(raw, cands, 1, {}, {}, fill, bad), InputError);
  EXPECT_EQ(ParseEvidence("choice"), NextRule::Evidence::kChoice);
  EXPECT_EQ(ToString(NextRule::Evidence::kLackOfFit), "lack-of-fit");
  EXPECT_THROW(ParseEvidence("ratio"), InputError);
}


// ---- Bayesian D (DuMouchel & Jones 1994) ------------------------------------------------------

std::set<int> PickSet(const PowerLawDesign& d) {
  std::set<int> s;
  for (const auto& p : d.picks) s.insert(p.candidate);
  return s;
}

// One input varies: ln(diameter / 50 mm) = t in {-1, -0.5, 0, 0.5, 1}, 3 screws. Primary terms
// (1, z), z = t / sqrt(0.5) (standardized); the potential square z^2 is symmetric, so orthogonal
// to z; its residual on 1 is prop. to t^2 - 0.5, range-scaled to q = (1, -0.5, -1, -0.5, 1).
// For t = {-1, 0, 1}: X'X = [[3, 0, 1], [0, 4, 0], [1, 0, 3]], det 32, and det(F'F) = 12; for
// t = {-1, +-0.5, 1}: det(X'X) = 18, det(F'F) = 13 (the D-optimal ones). With the prior k =
// 1 / tau^2 on q, det(X'X + k e e') = det(X'X) + k det(F'F): 32 + 12 k against 18 + 13 k, so the
// mid-level screw wins while k < 14 (tau > 0.267): at tau = 1, ln det = ln 44.
std::vector<ProcessInputs> FiveDiameters() {
  std::vector<ProcessInputs> c;
  for (double t : {-1.0, -0.5, 0.0, 0.5, 1.0})
    c.push_back(ProcessInputs::FromArray({62, 50 * std::exp(t), 10, 5, 180}));
  return c;
}

TEST(Design, BayesDTakesTheMidLevelByHand) {
  const auto c = FiveDiameters();
  const auto b = DesignPowerLaw(c, 3, Criterion::kBayesD, 0, kInsideAuto, {}, FillRule::kMaximin,
                                {BayesPrior::Terms::kSquares, 1.0});
  EXPECT_EQ(PickSet(b), (std::set<int>{0, 2, 4}));
  EXPECT_NEAR(b.bayes_log_det, std::log(44.0), 1e-9);
  EXPECT_EQ(b.potential_terms, 1);
  EXPECT_EQ(b.inside, 0);  // the automatic --inside is 0 with bayes-d
  // Interactions need two varying inputs: none here, the same design.
  const auto bi = DesignPowerLaw(c, 3, Criterion::kBayesD, 0, 0, {}, FillRule::kMaximin,
                                 {BayesPrior::Terms::kSquaresInteractions, 1.0});
  EXPECT_EQ(PickSet(bi), PickSet(b));
  const auto d = PickSet(DesignPowerLaw(c, 3, Criterion::kD, 0, 0));
  EXPECT_TRUE(d == (std::set<int>{0, 1, 4}) || d == (std::set<int>{0, 3, 4}));
  // Past k = 14 (tau = 0.2: k = 25) the D-optimal screws win: 18 + 13 k = 343 > 32 + 12 k = 332.
  const auto small = DesignPowerLaw(c, 3, Criterion::kBayesD, 0, 0, {}, FillRule::kMaximin,
                                    {BayesPrior::Terms::kSquares, 0.2});
  EXPECT_EQ(PickSet(small).count(2), 0u);
  EXPECT_NEAR(small.bayes_log_det, std::log(343.0), 1e-9);
}

TEST(Design, BayesDWithTinyTauIsTheDOptimalDesign) {
  std::mt19937 rng(11);
  const auto cands = RandomList(rng, 60);
  for (auto terms : {BayesPrior::Terms::kSquares, BayesPrior::Terms::kSquaresInteractions})
    for (int count : {6, 8, 12}) {
      const auto d = DesignPowerLaw(cands, count, Criterion::kD, 0, 0);
      const auto b = DesignPowerLaw(cands, count, Criterion::kBayesD, 0, 0, {},
                                    FillRule::kMaximin, {terms, 1e-3});
      EXPECT_EQ(PickSet(b), PickSet(d)) << "count " << count;
      EXPECT_NEAR(b.log_det, d.log_det, 1e-9);
    }
}

TEST(Design, BayesDRespectsTheListAndTheRanges) {
  const auto r = PaperRanges();
  const auto g3 = GridCandidates(r, 3);
  for (auto terms : {BayesPrior::Terms::kSquares, BayesPrior::Terms::kSquaresInteractions}) {
    const auto b = DesignPowerLaw(g3, 12, Criterion::kBayesD, 0, kInsideAuto, {},
                                  FillRule::kMaximin, {terms, 1.0});
    ASSERT_EQ(PickSet(b).size(), 12u);
    EXPECT_EQ(b.potential_terms, terms == BayesPrior::Terms::kSquares ? 5 : 15);
    int mid = 0;  // coordinates at the grid's middle level, where a bend shows
    for (int c : PickSet(b)) {
      ASSERT_GE(c, 0);
      ASSERT_LT(c, static_cast<int>(g3.size()));
      const auto a = g3[c].ToArray();
      for (int j = 0; j < 5; ++j) {
        EXPECT_GE(a[j], r.lo[j]);
        EXPECT_LE(a[j], r.hi[j]);
        mid += a[j] != r.lo[j] && a[j] != r.hi[j];
      }
    }
    EXPECT_GT(mid, 0);
    // A squared log input takes one value over two levels: no potential square survives; the
    // design is then the D-optimal one (squares) or spends the prior on the 10 interactions.
    const auto g2 = GridCandidates(r, 2);
    const auto b2 = DesignPowerLaw(g2, 8, Criterion::kBayesD, 0, 0, {}, FillRule::kMaximin,
                                   {terms, 1.0});
    EXPECT_EQ(b2.potential_terms, terms == BayesPrior::Terms::kSquares ? 0 : 10);
  }
  const auto d = DesignPowerLaw(g3, 12, Criterion::kD, 0, 0);  // the D design: corners only
  for (int c : PickSet(d))
    for (int j = 0; j < 5; ++j)
      EXPECT_TRUE(g3[c].ToArray()[j] == r.lo[j] || g3[c].ToArray()[j] == r.hi[j]);
}

TEST(Design, BayesDBadRequestsAreNamed) {
  const auto c = FiveDiameters();
  for (double tau : {0.0, -1.0, std::nan("")})
    EXPECT_THROW(DesignPowerLaw(c, 3, Criterion::kBayesD, 0, 0, {}, FillRule::kMaximin,
                                {BayesPrior::Terms::kSquares, tau}),
                 InputError);
  EXPECT_THROW(ParsePotentialTerms("cubes"), InputError);
  EXPECT_EQ(ParseCriterion("bayes-d"), Criterion::kBayesD);
  EXPECT_EQ(ToString(ParsePotentialTerms("squares+interactions")), "squares+interactions");
  EXPECT_THROW(DesignPowerLaw(c, 1, Criterion::kBayesD), InputError);  // below 2 coefficients
}

}  // namespace
}  // namespace whirl::design
