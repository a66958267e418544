// family/family.h: the choice finds the power law in a power-law table, every candidate predicts
// through its transform, the calibrated GP covers fresh data, the coverage rule on hand-computed
// cases, candidate names, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <utility>

#include "core/csv.h"
#include "family/family.h"
#include "support/expect_error.h"
#include "support/power_law_table.h"

namespace whirl::family {
namespace {

using test::MakeTable;

double MaxRelativeError(const FamilyModel& m, const ProcessTable& test) {
  const std::vector<FamilyPrediction> p = PredictFamily(m, test.inputs);
  double worst = 0;
  for (std::size_t q = 0; q < p.size(); ++q)
    for (int k = 0; k < 2; ++k)
      worst = std::max(worst, std::abs(p[q].mean.ToArray()[k] / test.targets[q].ToArray()[k] - 1));
  return worst;
}

TEST(FamilyChoice, FindsThePowerLawAndItsTableIsConsistent) {
  const ProcessTable train = MakeTable(20, 0.01, 1), test = MakeTable(200, 0.0, 2);
  ChoiceOptions o;
  o.candidates = {ParseCandidate("linear/identity"), ParseCandidate("linear/log"),
                  ParseCandidate("network-h6/identity")};
  o.stack = false;               // the hard choice (whirl train --choice hard)
  o.one_standard_error = false;  // the plain lowest error (tested alone below)
  o.closed_form_loo = false;     // 5-fold refits for every candidate
  for (const bool per_output : {false, true}) {
    o.per_output = per_output;
    const Choice c = ChooseFamily(train, o);
    ASSERT_EQ(c.table.size(), 3u);
    ASSERT_EQ(c.models.size(), 1u) << c.Describe() << nlohmann::json(c.table).dump();
    EXPECT_EQ(c.models[0].candidate.Name(), "linear/log");
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(c.table[c.chosen[k]].candidate.Name(), "linear/log");
      for (const CvRow& r : c.table)
        EXPECT_GE(per_output ? r.cv_rmse(k) : r.score,
                  per_output ? c.table[c.chosen[k]].cv_rmse(k) : c.table[c.chosen[k]].score);
    }
    EXPECT_LT(MaxRelativeError(c.models[0], test), 0.03);
  }
  o.closed_form_loo = true;  // linear fits by closed-form LOO, the network by 5-fold refits
  o.per_output = false;
  EXPECT_EQ(ChooseFamily(train, o).Describe(),
            "max_elongation_um: linear/log, settle_time_s: linear/log");
}

TEST(FamilyChoice, OutputsMayComeFromDifferentFamilies) {
  // Output 0 a power law, output 1 a curved function of the inputs: per output, the choice
  // takes the power law for the first and a GP on raw columns for the second.
  ProcessTable train = MakeTable(30, 0.01, 11);
  const ProcessTable curved = MakeTable(30, 0.01, 11, true);
  for (std::size_t q = 0; q < train.targets.size(); ++q)
    train.targets[q].settle_time_s = curved.targets[q].settle_time_s;
  ChoiceOptions o;
  o.candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-matern52-constant/identity")};
  const Choice c = ChooseFamily(train, o);
  EXPECT_EQ(c.Describe(),
            "max_elongation_um: linear/log, settle_time_s: gp-matern52-constant/identity");
  ASSERT_EQ(c.models.size(), 2u);
  const std::vector<FamilyPrediction> p = PredictChoice(c, train.inputs);
  const std::vector<FamilyPrediction> p0 = PredictFamily(c.models[0], train.inputs);
  const std::vector<FamilyPrediction> p1 = PredictFamily(c.models[1], train.inputs);
  EXPECT_EQ(p[3].mean.max_elongation_um, p0[3].mean.max_elongation_um);
  EXPECT_EQ(p[3].stddev.settle_time_s, p1[3].stddev.settle_time_s);
}

TEST(FamilyChoice, ALinearNetworkOnLogColumnsIsAPowerLaw) {
  const ProcessTable train = MakeTable(20, 0.0, 3), test = MakeTable(100, 0.0, 4);
  const FamilyModel log_net = FitCandidate(train, ParseCandidate("network-h0/log"), {});
  const FamilyModel raw_net = FitCandidate(train, ParseCandidate("network-h0/identity"), {});
  EXPECT_LT(MaxRelativeError(log_net, test), 0.01);
  EXPECT_GT(MaxRelativeError(raw_net, test), 0.05);  // a linear fit on raw columns is not
  ExpectInputError(
      [&] {
        std::vector<ProcessInputs> in = {test.inputs[0]};
        in[0].pitch_mm = 0.0;
        PredictFamily(log_net, in);
      },
      "pitch_mm = 0");
}

TEST(FamilyChoice, SameResultOnAnyThreadCountAndWithKFoldScoring) {
  const ProcessTable train = MakeTable(24, 0.05, 31, true), test = MakeTable(50, 0.0, 32, true);
  for (const bool loo : {true, false}) {
    ChoiceOptions o;
    o.closed_form_loo = loo;
    o.candidates.push_back(ParseCandidate("network-h4/identity"));
    const Choice one = ChooseFamily(train, o);
    o.fit.threads = 2;
    const Choice two = ChooseFamily(train, o);
    ASSERT_EQ(one.Describe(), two.Describe());
    const std::vector<FamilyPrediction> a = PredictChoice(one, test.inputs);
    const std::vector<FamilyPrediction> b = PredictChoice(two, test.inputs);
    for (std::size_t q = 0; q < a.size(); ++q)
      for (int k = 0; k < 2; ++k) {
        EXPECT_EQ(a[q].mean.ToArray()[k], b[q].mean.ToArray()[k]);
        EXPECT_EQ(a[q].stddev.ToArray()[k], b[q].stddev.ToArray()[k]);
      }
    for (std::size_t c = 0; c < one.table.size(); ++c)
      EXPECT_EQ(one.table[c].score, two.table[c].score);
  }
}

TEST(FamilyChoice, ChosenModelsEqualAFreshCalibratedFit) {
  // Whether the choice reuses its held-out residuals for the calibration (K-fold scoring) or
  // calibrates afterwards (closed-form LOO scoring), the chosen model predicts as FitCandidate.
  const ProcessTable train = MakeTable(24, 0.05, 41, true), test = MakeTable(30, 0.0, 42, true);
  for (const bool loo : {true, false})
    for (const char* name : {"linear/log", "gp-matern52-constant/identity"}) {
      ChoiceOptions o;
      o.closed_form_loo = loo;
      o.candidates = {ParseCandidate(name)};
      const Choice c = ChooseFamily(train, o);
      const FamilyModel fresh = FitCandidate(train, ParseCandidate(name), o.fit);
      const std::vector<FamilyPrediction> a = PredictChoice(c, test.inputs);
      const std::vector<FamilyPrediction> b = PredictFamily(fresh, test.inputs);
      for (std::size_t q = 0; q < a.size(); ++q)
        for (int k = 0; k < 2; ++k) {  // the choice's sd: the model's times Choice::sd_scale
          EXPECT_NEAR(a[q].mean.ToArray()[k], b[q].mean.ToArray()[k], 1e-9) << name;
          EXPECT_NEAR(a[q].stddev.ToArray()[k], c.sd_scale[k] * b[q].stddev.ToArray()[k], 1e-9)
              << name << " loo " << loo;
        }
      EXPECT_EQ(c.models[0].calibration, fresh.calibration);
    }
}

TEST(FamilyChoice, EveryChosenModelOfTheDefaultIsItsCandidatesOwnCalibratedFit) {
  // The default candidates below 70 rows: GPs are judged by refits from fixed starting points and
  // fitted on all rows only once chosen; what the choice returns is bit for bit FitCandidate's
  // fit and calibration of that candidate.
  ChoiceOptions o;
  o.fit.threads = 1;
  const ProcessTable test = MakeTable(30, 0.0, 42, true);
  int gps = 0;
  for (unsigned seed = 1; seed <= 4; ++seed)
    for (const bool bent : {false, true}) {
      const ProcessTable t =
          bent ? test::MakeBentTable(24, 0.03, 0.5, seed) : MakeTable(24, 0.05, seed, true);
      const Choice c = ChooseFamily(t, o);
      for (const FamilyModel& m : c.models) {
        gps += m.candidate.family == Family::kGaussianProcess;
        const FamilyModel fresh = FitCandidate(t, m.candidate, o.fit);
        EXPECT_EQ(m.calibration, fresh.calibration);
        const std::vector<FamilyPrediction> a = PredictFamily(m, test.inputs);
        const std::vector<FamilyPrediction> b = PredictFamily(fresh, test.inputs);
        for (std::size_t q = 0; q < a.size(); ++q)
          for (int k = 0; k < 2; ++k) {
            EXPECT_EQ(a[q].mean.ToArray()[k], b[q].mean.ToArray()[k]) << m.candidate.Name();
            EXPECT_EQ(a[q].stddev.ToArray()[k], b[q].stddev.ToArray()[k]) << m.candidate.Name();
          }
      }
    }
  EXPECT_GT(gps, 0);  // the tables choose a GP somewhere
}

TEST(FamilyChoice, ANetworkThatTakesPartIsItsCandidatesOwnCalibratedFit) {
  // A network that takes part is calibrated from the choice's own refits (family.cpp,
  // FitNetwork's fold_fits) instead of refitting them: the model is bit for bit FitCandidate's.
  // On this generated Friedman #2/#3 table of 100 rows (scripts/bench_tables.py) the default
  // stacks the network into both outputs.
  const ProcessTable t = ReadProcessTable(
      std::string(WHIRL_SOURCE_DIR) + "/tests/bench/data/friedman23_100.csv", true);
  ChoiceOptions o;
  o.fit.threads = 1;
  const Choice c = ChooseFamily(t, o);
  const ProcessTable test = MakeTable(30, 0.0, 42, true);
  int networks = 0;
  for (const FamilyModel& m : c.models) {
    if (m.candidate.family != Family::kNetwork) continue;
    ++networks;
    const FamilyModel fresh = FitCandidate(t, m.candidate, o.fit);
    EXPECT_EQ(m.calibration, fresh.calibration);
    for (int k = 0; k < 2; ++k)
      EXPECT_EQ(m.network.output_noise_variance(k), fresh.network.output_noise_variance(k)) << k;
    const std::vector<FamilyPrediction> a = PredictFamily(m, test.inputs);
    const std::vector<FamilyPrediction> b = PredictFamily(fresh, test.inputs);
    for (std::size_t q = 0; q < a.size(); ++q)
      for (int k = 0; k < 2; ++k) {
        EXPECT_EQ(a[q].mean.ToArray()[k], b[q].mean.ToArray()[k]);
        EXPECT_EQ(a[q].stddev.ToArray()[k], b[q].stddev.ToArray()[k]);
      }
  }
  EXPECT_EQ(networks, 1);
}

TEST(FamilyChoice, ClosedFormLeaveOneOutEqualsRefitsInOriginalUnits) {
  // linear/log: the held-out prediction of a refit without row i, mapped back by exp.
  const ProcessTable table = MakeTable(12, 0.05, 21);
  const FamilyModel m = FitCandidate(table, ParseCandidate("linear/log"), {}, false);
  const Eigen::MatrixXd sq = LeaveOneOutSquaredErrors(m, table);
  for (int i = 0; i < 12; ++i) {
    ProcessTable without = table;
    without.inputs.erase(without.inputs.begin() + i);
    without.targets.erase(without.targets.begin() + i);
    const FamilyModel mi = FitCandidate(without, ParseCandidate("linear/log"), {}, false);
    const FamilyPrediction p = PredictFamily(mi, {table.inputs[i]}).front();
    for (int k = 0; k < 2; ++k) {
      const double e = table.targets[i].ToArray()[k] - p.mean.ToArray()[k];
      EXPECT_NEAR(sq(k, i), e * e, 1e-9 * std::max(1.0, e * e)) << "row " << i << " output " << k;
    }
  }
  ChoiceOptions o;
  o.closed_form_loo = true;
  o.candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-se-constant/identity")};
  const Choice c = ChooseFamily(table, o);
  EXPECT_NEAR(c.table[0].cv_rmse(0), std::sqrt(sq.row(0).mean()), 1e-12);
}

TEST(FamilyCalibration, CalibratedGpCoversFreshData) {
  // 40 noisy rows of a smooth non-power law, 5 tables: mean +-1 / +-2 sd coverage of 2000 fresh
  // rows inside the targets of issue 40 (60-76 % and 90-98 %), with a margin for 5 tables.
  const ProcessTable test = MakeTable(2000, 0.05, 6, true);
  for (const char* name : {"gp-matern52-constant/identity", "gp-se-constant/log"}) {
    double in1[2] = {0, 0}, in2[2] = {0, 0};
    for (unsigned seed = 5; seed < 10; ++seed) {
      const FamilyModel m = FitCandidate(MakeTable(40, 0.05, seed, true), ParseCandidate(name), {});
      const std::vector<FamilyPrediction> p = PredictFamily(m, test.inputs);
      for (int k = 0; k < 2; ++k)
        for (std::size_t q = 0; q < p.size(); ++q) {
          const double r = std::abs(test.targets[q].ToArray()[k] - p[q].mean.ToArray()[k]);
          in1[k] += (r <= p[q].stddev.ToArray()[k]) / 10000.0;
          in2[k] += (r <= 2 * p[q].stddev.ToArray()[k]) / 10000.0;
        }
    }
    for (int k = 0; k < 2; ++k) {
      EXPECT_GE(in1[k], 0.58) << name << " output " << k;
      EXPECT_LE(in1[k], 0.80) << name << " output " << k;
      EXPECT_GE(in2[k], 0.88) << name << " output " << k;
      EXPECT_LE(in2[k], 0.99) << name << " output " << k;
    }
  }
}

TEST(FamilyChoice, OneStandardErrorRuleOnHandComputedCases) {
  Eigen::VectorXd a(4), b(4);
  a << 1, 1, 1, 1;
  b << 0.9, 0.9, 0.9, 0.9;  // lower on every row: d = 0.1 with sd 0
  EXPECT_EQ(SimplestWithinOneStandardError({a, b}), 1);
  a << 1, 2, 1, 2;          // mean 1.5
  b << 1.5, 1.0, 1.2, 1.5;  // mean 1.3; d = (-0.5, 1, -0.2, 0.5), mean 0.2, sd sqrt(0.46)
  EXPECT_EQ(SimplestWithinOneStandardError({a, b}), 0);  // 0.2 <= sqrt(0.46) / 2 = 0.339
  a << 1, 2.4, 1, 2;  // mean 1.6; d = (-0.5, 1.4, -0.2, 0.5), mean 0.3, sd 0.845
  EXPECT_EQ(SimplestWithinOneStandardError({a, b}), 0);  // 0.3 <= 0.845 / 2
  a << 2, 2, 2, 2.1;  // d = (0.5, 1, 0.8, 0.6): mean 0.725 > se 0.11
  EXPECT_EQ(SimplestWithinOneStandardError({a, b}), 1);
  EXPECT_EQ(SimplestWithinOneStandardError({b, a}), 0);
  ExpectInputError([] { SimplestWithinOneStandardError({}); }, "no candidates");
}

TEST(FamilyChoice, LeavingTheFirstCandidateOnHandComputedCases) {
  Eigen::VectorXd first(4), other(4);
  first << 4, 0, 4, 0;
  other << 1, 1, 1, 1;  // d = (3, -1, 3, -1): mean 1, sd sqrt(16 / 3), se 1.1547
  EXPECT_TRUE(BeatsFirst(first, other, 0.5, 0, 4));   // 1 > 0.577
  EXPECT_FALSE(BeatsFirst(first, other, 1.0, 0, 4));  // 1 <= 1.155
  EXPECT_TRUE(BeatsFirst(first, other, 0.5, 1, 2));   // blocks (6, -2): one positive
  EXPECT_FALSE(BeatsFirst(first, other, 0.5, 2, 2));  // not two
  EXPECT_TRUE(BeatsFirst(first, other, 0.5, 9, 1));   // one block: its sum 4 > 0
  EXPECT_FALSE(BeatsFirst(other, first, 0.0, 0, 4));  // a higher mean never beats
  EXPECT_FALSE(BeatsFirst(first, first, 0.0, 0, 4));  // nor an equal one
  ExpectInputError([&] { BeatsFirst(first, Eigen::VectorXd(3), 1, 0, 4); }, "equal sizes");
  ExpectInputError([&] { BeatsFirst(first, other, 1, 0, 0); }, "blocks >= 1");
}

// ChoiceOptions::leave_first_se: on 20-row power-law tables with 8 % noise the
// one-standard-error rule alone leaves the power law on some tables (a GP or the raw linear fit
// wins the 5-fold refits by chance); the default leaves it on fewer.
TEST(FamilyChoice, ThePowerLawIsLeftOnlyForACandidateThatBeatsItClearly) {
  ChoiceOptions off, hard;  // the hard choice (the rule under test is not the stack's)
  off.stack = hard.stack = false;
  off.leave_first_se = 0;
  int left_off = 0, left_default = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const ProcessTable t = MakeTable(20, 0.08, seed);
    const Choice a = ChooseFamily(t, off), b = ChooseFamily(t, hard);
    for (int k = 0; k < 2; ++k) {
      left_off += a.table[a.chosen[k]].candidate.Name() != "linear/log";
      left_default += b.table[b.chosen[k]].candidate.Name() != "linear/log";
    }
  }
  EXPECT_GT(left_off, 0);  // the planted case exists
  EXPECT_LT(left_default, left_off);
}

// ChoiceOptions::lowest_gp: a chosen GP is the GP with the lowest held-out error of its output
// (the one-standard-error rule alone may take a simpler GP within one standard error of it).
TEST(FamilyChoice, AChosenGpIsTheLowestGp) {
  ChoiceOptions on, off;
  on.leave_first_se = off.leave_first_se = 0;  // every GP takes part
  off.lowest_gp = false;
  ASSERT_TRUE(on.lowest_gp);
  int violations_off = 0, gps = 0;
  for (unsigned seed = 1; seed <= 12; ++seed)
    for (const bool curved : {false, true}) {
      const ProcessTable t = curved ? MakeTable(24, 0.05, seed, true)
                                    : test::MakeBentTable(24, 0.03, 0.5, seed);
      for (const bool lowest : {true, false}) {
        const Choice c = ChooseFamily(t, lowest ? on : off);
        for (int k = 0; k < 2; ++k) {
          const CvRow& chosen = c.table[c.chosen[k]];
          if (chosen.candidate.family != Family::kGaussianProcess) continue;
          bool lowest_gp = true;
          for (const CvRow& r : c.table)
            if (r.candidate.family == Family::kGaussianProcess && r.cv_rmse(k) < chosen.cv_rmse(k))
              lowest_gp = false;
          if (lowest) {
            ++gps;
            EXPECT_TRUE(lowest_gp) << "seed " << seed << " output " << k << ": " << c.Describe();
          } else {
            violations_off += !lowest_gp;
          }
        }
      }
    }
  EXPECT_GT(gps, 5);
  EXPECT_GT(violations_off, 0);  // the rule changes something on these tables
}

// GP candidates with a positive stacking weight in output k, as indices into c.table.
std::vector<int> WeightedGps(const Choice& c, int k) {
  std::vector<int> out;
  for (std::size_t j = 0; j < c.models.size(); ++j) {
    const bool weighted = c.weights[k].empty() ? static_cast<int>(j) == c.model_of_output[k]
                                               : c.weights[k][j] > 0;
    if (!weighted || c.models[j].candidate.family != Family::kGaussianProcess) continue;
    for (std::size_t r = 0; r < c.table.size(); ++r)
      if (c.table[r].candidate.Name() == c.models[j].candidate.Name())
        out.push_back(static_cast<int>(r));
  }
  return out;
}

// ChoiceOptions::lowest_gp_per_scale: below few_rows every stacked GP is the lowest of its column
// scale (at most one on log columns, one on raw columns; with every candidate past the gate), and
// on some tables a GP of each scale gets weight, which lowest_gp alone never allows; from few_rows
// rows the choice is the one without it.
TEST(FamilyChoice, LowestGpPerScaleStacksTheLowestGpOfEachColumnScale) {
  ChoiceOptions per_scale, lowest;
  per_scale.stack_gate_se = lowest.stack_gate_se = 0;  // every candidate past the gate
  per_scale.lowest_gp_per_scale = true;
  lowest.lowest_gp_per_scale = false;
  int two_scales = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    const ProcessTable t = test::MakeBentTable(24, 0.03, 0.5, seed);
    const Choice a = ChooseFamily(t, per_scale), b = ChooseFamily(t, lowest);
    for (int k = 0; k < 2; ++k) {
      const std::vector<int> gps = WeightedGps(a, k);
      EXPECT_LE(WeightedGps(b, k).size(), 1u) << b.Describe();
      std::array<int, 2> per = {0, 0};
      for (int g : gps) {
        ++per[a.table[g].candidate.log];
        for (const CvRow& r : a.table)
          if (r.candidate.family == Family::kGaussianProcess &&
              r.candidate.log == a.table[g].candidate.log) {
            EXPECT_GE(r.cv_rmse(k), a.table[g].cv_rmse(k)) << "seed " << seed << ": "
                                                           << a.Describe();
          }
      }
      EXPECT_LE(per[0], 1);
      EXPECT_LE(per[1], 1);
      two_scales += per[0] == 1 && per[1] == 1;
    }
  }
  EXPECT_GT(two_scales, 0);  // the option changes something on these tables
  const ProcessTable large = test::MakeBentTable(per_scale.few_rows, 0.03, 0.5, 1);
  EXPECT_EQ(ChooseFamily(large, per_scale).Describe(), ChooseFamily(large, lowest).Describe());
}

// ChoiceOptions::lowest_gp_per_scale_large: below few_rows the choice is the default's, bit for
// bit (and the default has it off). From few_rows rows the lowest GP of each column scale takes
// part (GpsThatTakePart, the same list for the stack and the hard choice): in the stack (every
// candidate past the gate, unshrunk) every weighted GP is the lowest of its scale, at most one
// per scale; in the hard choice (one-standard-error rule, simplest first, the log-column GP
// listed before the raw-column ones) a log-column GP within one standard error of a lower
// raw-column GP is chosen on some tables, which the default, with the lowest GP of all alone,
// never allows.
TEST(FamilyChoice, LowestGpPerScaleLargeLetsTheLowestGpOfEachScaleTakePartFromFewRows) {
  ChoiceOptions per_scale, lowest;
  EXPECT_FALSE(lowest.lowest_gp_per_scale_large);
  per_scale.lowest_gp_per_scale_large = true;
  // The held-out slot, which the per-scale rule refines (gp_slot_large overrides it).
  per_scale.gp_slot_large = lowest.gp_slot_large = GpSlot::kHeldOut;
  const ProcessTable small = test::MakeBentTable(24, 0.03, 0.5, 1);
  EXPECT_EQ(ChooseFamily(small, per_scale).Describe(), ChooseFamily(small, lowest).Describe());
  for (ChoiceOptions* o : {&per_scale, &lowest}) {
    o->candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-matern52-linear/log"),
                     ParseCandidate("gp-matern52-constant/identity"),
                     ParseCandidate("gp-se-constant/identity")};
    o->stack_gate_se_large = 0;                             // every candidate past the gate
    o->stack_start_se_large = o->stack_full_se_large = -1;  // the unshrunk stack
    o->leave_first_se_large = 0;                            // the hard choice: every candidate
  }
  ChoiceOptions hard_per_scale = per_scale, hard_lowest = lowest;
  hard_per_scale.stack = hard_lowest.stack = false;
  const auto is_gp = [](const CvRow& r) { return r.candidate.family == Family::kGaussianProcess; };
  int log_within_one_se = 0;
  for (unsigned seed = 1; seed <= 12; ++seed) {
    const int rows = per_scale.few_rows + 10 * (seed % 2);
    const ProcessTable t = seed > 6 ? test::MakeTable(rows, 0.15, seed, true)
                                    : test::MakeBentTable(rows, 0.15, 0.5, seed);
    const Choice a = ChooseFamily(t, per_scale);
    for (int k = 0; k < 2; ++k) {
      std::array<int, 2> per = {0, 0};
      for (int g : WeightedGps(a, k)) {
        ++per[a.table[g].candidate.log];
        for (const CvRow& r : a.table)
          if (is_gp(r) && r.candidate.log == a.table[g].candidate.log) {
            EXPECT_GE(r.cv_rmse(k), a.table[g].cv_rmse(k))
                << "seed " << seed << ": " << a.Describe();
          }
      }
      EXPECT_LE(per[0], 1);
      EXPECT_LE(per[1], 1);
    }
    const Choice h = ChooseFamily(t, hard_per_scale), d = ChooseFamily(t, hard_lowest);
    for (int k = 0; k < 2; ++k) {
      const CvRow &ch = h.table[h.chosen[k]], &cd = d.table[d.chosen[k]];
      for (const CvRow& r : d.table)  // the default: only the lowest GP of all takes part
        if (is_gp(cd) && is_gp(r)) {
          EXPECT_GE(r.cv_rmse(k), cd.cv_rmse(k)) << d.Describe();
        }
      log_within_one_se += is_gp(ch) && ch.candidate.log && is_gp(cd) && !cd.candidate.log;
    }
  }
  EXPECT_GT(log_within_one_se, 0);  // the option changes the list on these tables
}

// ChoiceOptions::refit_lowest_gp_rows: per output the GP with the lowest closed-form
// leave-one-out error keeps the held-out errors that refitting every GP gives it (the same
// folds, fixed starts), the other GP keeps its closed-form leave-one-out errors, and no GP but
// the refitted one gets weight.
TEST(FamilyChoice, RefitLowestGpJudgesOnlyTheLowestGpByRefits) {
  ChoiceOptions loo, every, lowest;
  for (ChoiceOptions* o : {&loo, &every, &lowest})
    o->candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-matern52-linear/log"),
                     ParseCandidate("gp-matern52-constant/identity")};
  every.few_rows = lowest.few_rows = 101;
  lowest.refit_lowest_gp_rows = 70;
  const ProcessTable t = test::MakeBentTable(100, 0.03, 0.5, 2);
  const Choice a = ChooseFamily(t, loo), b = ChooseFamily(t, every), c = ChooseFamily(t, lowest);
  for (int k = 0; k < 2; ++k) {
    const int g = a.table[1].cv_rmse(k) <= a.table[2].cv_rmse(k) ? 1 : 2, other = 3 - g;
    EXPECT_NEAR(c.table[g].cv_rmse(k), b.table[g].cv_rmse(k), 1e-9 * b.table[g].cv_rmse(k));
    EXPECT_NE(c.table[g].cv_rmse(k), a.table[g].cv_rmse(k));
    EXPECT_EQ(c.table[other].cv_rmse(k), a.table[other].cv_rmse(k));
    for (int w : WeightedGps(c, k)) EXPECT_EQ(w, g) << c.Describe();
  }
}

// ChoiceOptions::refit_hyperparameter_rows: a subset of every row of the refits is the choice
// without it, bit for bit; a smaller one (or looser refit tolerances) changes the GP's held-out
// errors (its refits) and neither the linear fit's errors nor the GP fitted on the whole table
// (GpOptions' own settings); below single_start_rows rows it changes nothing.
TEST(FamilyChoice, RefitHyperparameterRowsSubsetsOnlyTheRefits) {
  ChoiceOptions every, all_rows, subset, loose;
  for (ChoiceOptions* o : {&every, &all_rows, &subset, &loose}) {
    o->candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-matern52-linear/log")};
    o->few_rows = 101;
    o->stack_gate_se = o->stack_gate_se_large = 0;  // the GP gets weight
  }
  all_rows.refit_hyperparameter_rows = 100;
  subset.refit_hyperparameter_rows = 40;
  loose.refit_function_tolerance = 0.1;
  loose.refit_gradient_tolerance = 1;
  const ProcessTable t = test::MakeBentTable(100, 0.03, 0.5, 2);
  const Choice a = ChooseFamily(t, every), b = ChooseFamily(t, all_rows);
  EXPECT_EQ(b.Describe(), a.Describe());
  for (int k = 0; k < 2; ++k) EXPECT_EQ(b.table[1].cv_rmse(k), a.table[1].cv_rmse(k));
  for (const ChoiceOptions* o : {&subset, &loose}) {
    const Choice c = ChooseFamily(t, *o);
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(c.table[0].cv_rmse(k), a.table[0].cv_rmse(k));
      EXPECT_NE(c.table[1].cv_rmse(k), a.table[1].cv_rmse(k));
    }
    int gps = 0;
    for (const FamilyModel& m : c.models)
      for (const FamilyModel& n : a.models) {
        if (m.gps.empty() || m.candidate.Name() != n.candidate.Name()) continue;
        for (std::size_t k = 0; k < m.gps.size(); ++k, ++gps)
          EXPECT_EQ(m.gps[k].theta, n.gps[k].theta) << "output " << k;
      }
    EXPECT_GT(gps, 0) << c.Describe();
  }
  const ProcessTable small = test::MakeBentTable(24, 0.03, 0.5, 2);
  const Choice d = ChooseFamily(small, every), e = ChooseFamily(small, subset);
  EXPECT_EQ(e.Describe(), d.Describe());
  for (int k = 0; k < 2; ++k) EXPECT_EQ(e.table[1].cv_rmse(k), d.table[1].cv_rmse(k));
}

TEST(FamilyChoice, GpLooHyperparameterPenaltyScalesOnlyTheGpsLeaveOneOut) {
  ChoiceOptions plain, penalized;
  for (ChoiceOptions* o : {&plain, &penalized})
    o->candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-se-constant/identity"),
                     ParseCandidate("gp-se-iso-constant/identity")};
  penalized.gp_loo_hyperparameter_penalty = 2;
  const ProcessTable t = test::MakeBentTable(100, 0.03, 0.5, 2);
  const Choice a = ChooseFamily(t, plain), b = ChooseFamily(t, penalized);
  // 100 rows, five inputs: the ARD GP fits 5 length scales + signal + noise sd, the isotropic 3.
  const double ard = std::sqrt(1 + 2.0 * 7 / 100), iso = std::sqrt(1 + 2.0 * 3 / 100);
  for (int k = 0; k < 2; ++k) {
    EXPECT_EQ(b.table[0].cv_rmse(k), a.table[0].cv_rmse(k));
    EXPECT_NEAR(b.table[1].cv_rmse(k), ard * a.table[1].cv_rmse(k), 1e-12 * a.table[1].cv_rmse(k));
    EXPECT_NEAR(b.table[2].cv_rmse(k), iso * a.table[2].cv_rmse(k), 1e-12 * a.table[2].cv_rmse(k));
  }
  // The GPs themselves and their calibration do not change.
  int gps = 0;
  for (const FamilyModel& m : b.models)
    for (const FamilyModel& n : a.models) {
      if (m.gps.empty() || m.candidate.Name() != n.candidate.Name()) continue;
      for (std::size_t k = 0; k < m.gps.size(); ++k, ++gps) {
        EXPECT_EQ(m.gps[k].theta, n.gps[k].theta);
        EXPECT_EQ(m.gps[k].noise_variance, n.gps[k].noise_variance);
      }
    }
  EXPECT_GT(gps, 0) << a.Describe() << " / " << b.Describe();
  // Below few_rows the GPs are judged by refits: nothing is scaled.
  const ProcessTable small = test::MakeBentTable(30, 0.03, 0.5, 2);
  const Choice c = ChooseFamily(small, plain), d = ChooseFamily(small, penalized);
  EXPECT_EQ(d.Describe(), c.Describe());
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < 2; ++k) EXPECT_EQ(d.table[j].cv_rmse(k), c.table[j].cv_rmse(k));
}

// ln N(w | H b, s^2 K) over the rows of g (squared-exponential kernel), w in the units of the
// GP's column (ln y or y), b by generalized least squares of w, K of g's fitted hyperparameters
// on its standardized inputs, s its target scale; dense inverse and LU determinant.
double DenseLogDensity(const gp::Gp& g, const Eigen::VectorXd& w) {
  const int d = g.InputCount(), n = static_cast<int>(w.size());
  Eigen::MatrixXd k(n, n);
  for (int p = 0; p < n; ++p)
    for (int q = 0; q < n; ++q)
      k(p, q) =
          std::exp(2 * g.theta(d)) *
          std::exp(
              -0.5 *
              ((g.z.col(p) - g.z.col(q)).array() / g.theta.head(d).array().exp()).square().sum());
  k.diagonal().array() += g.SigmaN2();
  k *= g.target_scale * g.target_scale;
  Eigen::MatrixXd h(n, gp::MeanSize(g.mean, d));
  h.col(0).setOnes();
  if (g.mean == gp::Mean::kLinear) h.rightCols(d) = g.z.transpose();
  const Eigen::MatrixXd ki = k.inverse();
  const Eigen::VectorXd r = w - h * ((h.transpose() * ki * h).inverse() * h.transpose() * ki * w);
  return -0.5 * r.dot(ki * r) - 0.5 * std::log(k.fullPivLu().determinant()) -
         0.5 * n * std::log(2 * 3.14159265358979323846);
}

// GpLogEvidence: the GP's Gaussian density of its column (ln y or y) written out in the column's
// own units, minus sum ln y for a GP of ln y (the Jacobian of the log transform); and so the
// same shift for a GP of ln y and one of y when the targets change units.
TEST(FamilyGpEvidence, IsTheDensityOfTheTargetsWithTheJacobianOfTheLog) {
  const ProcessTable t = MakeTable(16, 0.05, 3, true);
  ProcessTable milli = t;  // the targets in units 1000 times smaller
  for (Features& f : milli.targets)
    f = Features::FromArray({1000 * f.ToArray()[0], 1000 * f.ToArray()[1]});
  for (const char* name : {"gp-se-constant/log", "gp-se-linear/log", "gp-se-constant/identity"}) {
    const Candidate c = ParseCandidate(name);
    const FamilyModel m = FitCandidate(t, c, {}, false);
    const FamilyModel m1000 = FitCandidate(milli, c, {}, false);
    for (int k = 0; k < 2; ++k) {
      Eigen::VectorXd w(static_cast<Eigen::Index>(t.targets.size()));
      double sum_log_y = 0;
      for (std::size_t i = 0; i < t.targets.size(); ++i) {
        const double y = t.targets[i].ToArray()[k];
        w(static_cast<Eigen::Index>(i)) = c.log ? std::log(y) : y;
        sum_log_y += std::log(y);
      }
      const double expected = DenseLogDensity(m.gps[k], w) - (c.log ? sum_log_y : 0.0);
      EXPECT_NEAR(GpLogEvidence(m, k), expected, 1e-7 * std::abs(expected)) << name << " " << k;
      // y -> 1000 y: every density of y divides by 1000 per row.
      const double n = static_cast<double>(w.size());
      EXPECT_NEAR(GpLogEvidence(m1000, k) - GpLogEvidence(m, k), -n * std::log(1000.0), 1e-3)
          << name << " " << k;
    }
  }
  ExpectInputError([&] { GpLogEvidence(FitCandidate(t, ParseCandidate("linear/log"), {}), 0); },
                   "holds no GP");
}

// ChoiceOptions::gp_slot_large (kBic by default): below few_rows the choice is that of the
// held-out slot bit for bit, for every rule; from few_rows the one GP that takes part is the GP
// of highest GpLogEvidence (kBic: minus (q / 2) ln n), and on some of these tables that is not
// the GP of lowest held-out error (kHeldOut, the default before).
TEST(FamilyChoice, GpSlotLargeGivesTheSlotToTheHighestEvidenceFromFewRows) {
  EXPECT_EQ(ChoiceOptions().gp_slot_large, GpSlot::kBic);
  ChoiceOptions held;
  held.gp_slot_large = GpSlot::kHeldOut;
  const ProcessTable small = test::MakeBentTable(30, 0.03, 0.5, 1);
  const Choice s0 = ChooseFamily(small, held);
  for (const GpSlot slot : {GpSlot::kEvidence, GpSlot::kBic}) {
    ChoiceOptions o = held;
    o.gp_slot_large = slot;
    EXPECT_EQ(nlohmann::json(ChooseFamily(small, o)).dump(), nlohmann::json(s0).dump());
  }
  held.candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-matern52-linear/log"),
                     ParseCandidate("gp-matern52-constant/identity"),
                     ParseCandidate("gp-se-constant/identity")};
  held.stack_gate_se_large = 0;                               // every candidate past the gate
  held.stack_start_se_large = held.stack_full_se_large = -1;  // the unshrunk stack
  int differs = 0;
  for (const GpSlot slot : {GpSlot::kEvidence, GpSlot::kBic})
    for (unsigned seed = 1; seed <= 6; ++seed) {
      const ProcessTable t = seed > 3 ? test::MakeTable(held.few_rows, 0.15, seed, true)
                                      : test::MakeBentTable(held.few_rows, 0.15, 0.5, seed);
      ChoiceOptions o = held;
      o.gp_slot_large = slot;
      const Choice a = ChooseFamily(t, o), b = ChooseFamily(t, held);
      for (int k = 0; k < 2; ++k) {
        int best = -1, lowest = -1;
        double best_ev = 0;
        for (std::size_t c = 1; c < o.candidates.size(); ++c) {
          const FamilyModel m = FitCandidate(t, o.candidates[c], o.fit, false);
          const double n = static_cast<double>(m.gps[k].u.size());
          const double q = 7 + gp::MeanSize(m.gps[k].mean, 5);  // 5 lengths, signal, noise
          const double ev =
              GpLogEvidence(m, k) - (slot == GpSlot::kBic ? 0.5 * q * std::log(n) : 0);
          if (best < 0 || ev > best_ev) best = static_cast<int>(c), best_ev = ev;
          if (lowest < 0 || a.table[c].cv_rmse(k) < a.table[lowest].cv_rmse(k))
            lowest = static_cast<int>(c);
        }
        for (int g : WeightedGps(a, k))
          EXPECT_EQ(g, best) << "seed " << seed << ": " << a.Describe();
        for (int g : WeightedGps(b, k))
          EXPECT_EQ(g, lowest) << "seed " << seed << ": " << b.Describe();
        differs += best != lowest;
      }
    }
  EXPECT_GT(differs, 0);  // the option changes the slot on these tables
}

TEST(FamilyCalibration, CoverageNoiseOnHandComputedCases) {
  Eigen::VectorXd r(4), v = Eigen::VectorXd::Zero(4);
  r << 1, -2, 3, 4;
  EXPECT_NEAR(CoverageNoiseVariance(r, v), 9.0, 1e-9);  // 3 of 4 within sqrt(9)
  v(3) = 100;  // the 4th row is covered by its own variance
  EXPECT_NEAR(CoverageNoiseVariance(r, v), 4.0, 1e-9);
  v << 10, 10, 10, 0;
  EXPECT_EQ(CoverageNoiseVariance(r, v), 0.0);
  ExpectInputError([&] { CoverageNoiseVariance(r, v.head(2)); }, "4 residuals and 2");
}

TEST(FamilyCalibration, TwoSdCoverageOnHandComputedCases) {
  Eigen::VectorXd r(4), v = Eigen::VectorXd::Zero(4);
  r << 1, 1, 1, 4;
  EXPECT_NEAR(CoverageNoiseVariance(r, v), 1.0, 1e-9);  // 3 of 4 within sqrt(1)
  // +-2 sd must cover 95.45 %: all four, 2 sqrt(s2) >= 4.
  EXPECT_NEAR(CoverageNoiseVariance(r, v, true), 4.0, 1e-9);
  r << 1, 2, 3, 4;  // +-1 sd needs 9; 2 sqrt(9) = 6 covers all four
  EXPECT_NEAR(CoverageNoiseVariance(r, v, true), 9.0, 1e-9);
  v << 0, 0, 0, 12;  // the 4th: 4 (s2 + 12) >= 16 for any s2; +-1 sd: 3 of 4 at s2 = 4
  EXPECT_NEAR(CoverageNoiseVariance(r, v, true), 4.0, 1e-9);
}

TEST(FamilyCalibration, TwoSdCoversEveryLeaveOneOutResidualAtTwentyRows) {
  // One outlier among 20 rows: FitOptions::calibrate_two_sd raises the noise until +-2 sd covers
  // 95.45 % (at 20 rows: all) of the closed-form leave-one-out residuals, and keeps at least the
  // +-1 sd level of the 5-fold residuals.
  ProcessTable table = MakeTable(20, 0.01, 41);
  table.targets[7].max_elongation_um *= 1.3;
  FitOptions one, two;
  one.calibrate_two_sd = false;
  two.calibrate_two_sd = true;
  const Candidate c = ParseCandidate("linear/identity");
  const FamilyModel m1 = FitCandidate(table, c, one), m2 = FitCandidate(table, c, two);
  const Eigen::MatrixXd x = nn::InputMatrix(table.inputs), y = nn::TargetMatrix(table.targets);
  for (int k = 0; k < 2; ++k) {
    const double s2 = m2.linears[k].noise_variance;
    EXPECT_GE(s2, m1.linears[k].noise_variance) << "output " << k;
    const LinearLeaveOneOut loo = LeaveOneOutLinear(m2.linears[k], x, y.row(k).transpose());
    for (int i = 0; i < 20; ++i)
      EXPECT_LE(loo.residual(i) * loo.residual(i),
                4.0 * (s2 + loo.latent_variance(i)) * (1 + 1e-9))
          << "output " << k << " row " << i;
  }
  EXPECT_GT(m2.linears[0].noise_variance, 2.0 * m1.linears[0].noise_variance);
  EXPECT_NE(m2.calibration.find("+-2 sd 95.45 %"), std::string::npos) << m2.calibration;
}

// Two linear fits whose output-k intercepts differ by c: their fits differ by c everywhere, so
// FitDifferenceInSd is c / (population sd of the transformed output k).
TEST(FamilyEquivalence, FitDifferenceOnAHandComputedCase) {
  const ProcessTable t = MakeTable(20, 0.05, 21);
  FitOptions fit;
  const FamilyModel a = FitCandidate(t, ParseCandidate("linear/log"), fit, false);
  for (int k = 0; k < 2; ++k) {
    FamilyModel b = a;
    b.linears[k].coef(0) += 0.3;
    Eigen::VectorXd y(20);
    for (int q = 0; q < 20; ++q) y(q) = std::log(t.targets[q].ToArray()[k]);
    const double sd = std::sqrt((y.array() - y.mean()).square().mean());
    EXPECT_NEAR(FitDifferenceInSd(a, b, t, k), 0.3 / sd, 1e-12);
    EXPECT_NEAR(FitDifferenceInSd(b, a, t, k), 0.3 / sd, 1e-12);
    EXPECT_EQ(FitDifferenceInSd(a, b, t, 1 - k), 0.0);
    EXPECT_EQ(FitDifferenceInSd(a, a, t, k), 0.0);
  }
  const FamilyModel raw = FitCandidate(t, ParseCandidate("linear/identity"), fit, false);
  ExpectInputError([&] { FitDifferenceInSd(a, raw, t, 0); }, "must share their transform");
  ExpectInputError([&] { FitDifferenceInSd(a, a, t, 2); }, "output 2");
  EXPECT_EQ(FittedHyperparameters(ParseCandidate("gp-matern52-constant/log")), 7);
  EXPECT_EQ(FittedHyperparameters(ParseCandidate("gp-se-iso-constant/identity")), 3);
  EXPECT_EQ(FittedHyperparameters(ParseCandidate("linear/log")), 0);
}

ProcessTable BentTable(double noise, double bend, unsigned seed) {
  return test::MakeBentTable(20, noise, bend, seed);
}

// ChoiceOptions::equivalence_sd over many 20-row tables: a choice changes only from a GP whose fit
// lies within the threshold of the linear fit on its columns with more degrees of freedom than
// that fit, to a linear candidate, with a note that names both and the refit errors; on power laws (where a GP chosen by leave-one-out is a
// power law with a spurious bend) the rule sets GPs aside.
// (The rule is off by default: with GP held-out errors from refits at few rows it changes
// nothing; these tests switch it on, with the closed-form leave-one-out of GPs it was made for.)
ChoiceOptions EquivalenceOptions(double sd) {
  ChoiceOptions o;
  o.stack = false;  // the rule is the hard choice's (ChoiceOptions::equivalence_sd)
  o.equivalence_sd = sd;
  o.few_rows = 0;  // GP held-out errors by their closed-form leave-one-out
  o.leave_first_se = o.leave_first_se_large = 0;  // the rule under test alone
  o.leave_first_row_share = 0;
  return o;
}

TEST(FamilyEquivalence, ANearlyLinearGpAtFewRowsMustBeatTheLinearFamilyInRefits) {
  ChoiceOptions on = EquivalenceOptions(0.1), off = EquivalenceOptions(0);
  for (ChoiceOptions* o : {&on, &off})
    o->candidates = {ParseCandidate("linear/log"), ParseCandidate("linear/identity"),
                     ParseCandidate("gp-matern52-constant/log")};
  int changed = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const ProcessTable t = BentTable(0.04, 0.0, seed);
    const Choice a = ChooseFamily(t, off), b = ChooseFamily(t, on);
    const FamilyModel gp = FitCandidate(t, on.candidates[2], on.fit, false);
    const FamilyModel lin = FitCandidate(t, on.candidates[0], on.fit, false);
    for (int k = 0; k < 2; ++k) {
      EXPECT_TRUE(a.notes[k].empty());
      if (b.chosen[k] == a.chosen[k]) {
        EXPECT_TRUE(b.notes[k].empty()) << "seed " << seed << " " << b.notes[k];
        continue;
      }
      ++changed;
      EXPECT_EQ(a.chosen[k], 2) << "seed " << seed;  // with two linear candidates, only a GP
      EXPECT_LT(FitDifferenceInSd(gp, lin, t, k), on.equivalence_sd) << "seed " << seed;
      EXPECT_GT(gp::EffectiveDegreesOfFreedom(gp.gps[k]), 6.0) << "seed " << seed;
      EXPECT_EQ(b.table[b.chosen[k]].candidate.family, Family::kLinear) << "seed " << seed;
      const std::string start = std::string(kTargetColumns[k]) +
                                ": gp-matern52-constant/log set aside for " +
                                b.table[b.chosen[k]].candidate.Name() + ": at 20 rows";
      EXPECT_EQ(b.notes[k].rfind(start, 0), 0u) << b.notes[k];
      EXPECT_NE(b.notes[k].find("refitted on 5 folds its RMSE"), std::string::npos) << b.notes[k];
    }
  }
  EXPECT_GE(changed, 5);
}

// A real bend that is small against the output's spread but large against the noise (0.3 %
// noise): the GP that finds it is never set aside, and predicts new rows better than the power
// law. (A rule on the fit distance alone set it aside on every table.)
TEST(FamilyEquivalence, ARealBendAboveTheNoiseKeepsItsGp) {
  const ProcessTable test = BentTable(0.0, 0.5, 999);
  for (const bool rule : {true, false}) {
  // With the rule (and leave-one-out errors) and with the default (refits at few rows).
  ChoiceOptions o = rule ? EquivalenceOptions(0.1) : ChoiceOptions{};
  o.stack = false;  // the hard choice's rules (whirl train --choice hard)
  int gp = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const Choice c = ChooseFamily(BentTable(0.003, 0.5, seed), o);
    EXPECT_TRUE(c.notes[0].empty()) << "seed " << seed << ": " << c.notes[0];
    if (c.table[c.chosen[0]].candidate.family != Family::kGaussianProcess) continue;
    ++gp;
    ChoiceOptions power_law;
    power_law.candidates = {ParseCandidate("linear/log")};
    const Choice p = ChooseFamily(BentTable(0.003, 0.5, seed), power_law);
    double e_c = 0, e_p = 0;
    const auto pc = PredictChoice(c, test.inputs), pp = PredictChoice(p, test.inputs);
    for (std::size_t q = 0; q < test.inputs.size(); ++q) {
      const double y = test.targets[q].max_elongation_um;
      e_c += std::pow(std::log(pc[q].mean.max_elongation_um / y), 2);
      e_p += std::pow(std::log(pp[q].mean.max_elongation_um / y), 2);
    }
    EXPECT_LT(e_c, e_p) << "seed " << seed;
  }
  // The default's leave_first_se (2 standard errors to leave the power law at 20 rows) keeps the
  // power law on some of these tables, where the GP beats it by 1-2 standard errors only: the
  // price of not leaving it on power laws without a bend (docs/workpiece-history.md).
  EXPECT_GE(gp, rule ? 8 : 6) << "rule " << rule;
  }
}

// The rule's refits need 8 rows in every training split (the linear fit's 6 coefficients and
// 2 more): on tables of 8 and 9 rows (5 folds: splits of 6 and 7 rows) it leaves the choice
// alone; from 10 rows on it may change it. Either way a table the choice could fit without the
// rule it still fits.
TEST(FamilyEquivalence, SmallTablesTrainAsWithoutTheRule) {
  ChoiceOptions on = EquivalenceOptions(0.1), off = EquivalenceOptions(0);
  int fitted = 0;
  for (int rows : {8, 9, 10, 11})
    for (unsigned seed = 1; seed <= 15; ++seed) {
      const ProcessTable t = MakeTable(rows, 0.04, seed);
      Choice a;
      try {
        a = ChooseFamily(t, off);
      } catch (const InputError&) {
        continue;  // (the linear fits' own 5-fold calibration needs 8 rows per split, too)
      }
      ++fitted;
      const Choice b = ChooseFamily(t, on);
      if (rows < 10) {
        EXPECT_EQ(a.Describe(), b.Describe()) << rows << " rows, seed " << seed;
      }
    }
  EXPECT_GT(fitted, 5);
}

// At 10 rows per hyperparameter or more the rule never applies, however large the threshold;
// below it, with a threshold above any distance, every change is a GP giving way to a linear fit.
TEST(FamilyEquivalence, AppliesOnlyBelowTenRowsPerHyperparameter) {
  ChoiceOptions wide = EquivalenceOptions(1e9), off = EquivalenceOptions(0);
  for (const bool curved : {false, true}) {
    const ProcessTable big = MakeTable(70, 0.04, 5, curved);
    const Choice a = ChooseFamily(big, off), b = ChooseFamily(big, wide);
    EXPECT_EQ(a.Describe(), b.Describe());
    EXPECT_TRUE(b.notes[0].empty() && b.notes[1].empty());
  }
  int changed = 0, gp_at_70 = 0;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    const ProcessTable big = MakeTable(70, 0.04, seed);
    const Choice a = ChooseFamily(big, off), b = ChooseFamily(big, wide);
    EXPECT_EQ(a.Describe(), b.Describe()) << "seed " << seed;
    for (int k = 0; k < 2; ++k)
      gp_at_70 += a.table[a.chosen[k]].candidate.family == Family::kGaussianProcess;
    const ProcessTable small = MakeTable(25, 0.04, seed);
    const Choice c = ChooseFamily(small, off), d = ChooseFamily(small, wide);
    for (int k = 0; k < 2; ++k) {
      if (c.chosen[k] == d.chosen[k]) continue;
      ++changed;
      EXPECT_EQ(c.table[c.chosen[k]].candidate.family, Family::kGaussianProcess);
      EXPECT_EQ(d.table[d.chosen[k]].candidate.family, Family::kLinear);
    }
  }
  EXPECT_GT(gp_at_70, 0);  // else the 70-row equality would hold without the row limit
  EXPECT_GT(changed, 0);
}

TEST(FamilyStacking, WeightsOnHandComputedCases) {
  Eigen::MatrixXd p(2, 2);
  Eigen::VectorXd t(2);
  t << 0, 0;
  p << 1, -1, 1, -1;  // symmetric errors: the half-half mean is exact
  EXPECT_TRUE(ConvexStackWeights(p, t).isApprox(Eigen::Vector2d(0.5, 0.5), 1e-12));
  p << 0, 1, 0, 2;  // the first is exact: the unconstrained solution needs no second
  EXPECT_TRUE(ConvexStackWeights(p, t).isApprox(Eigen::Vector2d(1, 0), 1e-12));
  p << 1, 3, 1, 3;  // both above the target: the convex optimum is the nearer one alone
  EXPECT_TRUE(ConvexStackWeights(p, t).isApprox(Eigen::Vector2d(1, 0), 1e-12));
  ExpectInputError([&] { ConvexStackWeights(p, Eigen::VectorXd(3)); }, "one target per row");
}

TEST(FamilyStacking, WeightsBeatEveryPointOfASimplexGrid) {
  // Property over random cases: w >= 0, sum 1, and no point of a 0.01 grid of the simplex has a
  // lower squared error.
  std::mt19937 rng(3);
  std::normal_distribution<double> n01;
  for (int trial = 0; trial < 50; ++trial) {
    Eigen::MatrixXd p(8, 3);
    Eigen::VectorXd t(8);
    for (int i = 0; i < 8; ++i) {
      t(i) = n01(rng);
      for (int c = 0; c < 3; ++c) p(i, c) = t(i) + (c + 1) * 0.3 * n01(rng) + 0.2 * c;
    }
    const Eigen::VectorXd w = ConvexStackWeights(p, t);
    ASSERT_GE(w.minCoeff(), 0.0);
    ASSERT_NEAR(w.sum(), 1.0, 1e-12);
    const double sse = (t - p * w).squaredNorm();
    for (int a = 0; a <= 100; ++a)
      for (int b = 0; a + b <= 100; ++b) {
        const Eigen::Vector3d g(a / 100.0, b / 100.0, (100 - a - b) / 100.0);
        ASSERT_LE(sse, (t - p * g).squaredNorm() + 1e-12) << "trial " << trial;
      }
  }
}

TEST(FamilyStacking, WeightsDoNotDependOnACommonOffset) {
  // Sum w = 1, so target - predictions w does not change when target and predictions move by
  // the same offset, and neither may w. Four correlated candidates around a level of 1000 (a
  // Friedman #2 output), the first biased: solved in the predictions themselves, every support
  // set lost to rounding and the first came back alone on every trial.
  std::mt19937 rng(7);
  std::normal_distribution<double> n01;
  for (int trial = 0; trial < 20; ++trial) {
    Eigen::MatrixXd p(100, 4);
    Eigen::VectorXd t(100);
    for (int i = 0; i < 100; ++i) {
      t(i) = 300 * n01(rng);
      const double common = 30 * n01(rng);
      for (int c = 0; c < 4; ++c) p(i, c) = t(i) + common + (10 + 5 * c) * n01(rng) + (c ? 0 : 20);
    }
    const Eigen::VectorXd at_zero = ConvexStackWeights(p, t);
    const Eigen::VectorXd at_1000 =
        ConvexStackWeights(p.array() + 1000.0, t.array() + 1000.0);
    EXPECT_LT(at_zero(0), 0.5) << "the biased first candidate must not win: " << trial;
    EXPECT_TRUE(at_1000.isApprox(at_zero, 1e-6)) << at_1000.transpose() << " against "
                                                 << at_zero.transpose();
  }
}

TEST(FamilyStacking, ShrunkWeightsAreConvexAndMoveFromTheFirstToTheStack) {
  // Property over random cases: w >= 0, sum 1, w = (1 - a) e_1 + a ConvexStackWeights, a in
  // [0, 1] the hand-computed ramp of z between start_se and full_se.
  std::mt19937 rng(5);
  std::normal_distribution<double> n01;
  int full = 0, none = 0, between = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int n = 8 + trial % 30;
    Eigen::MatrixXd p(n, 4);
    Eigen::VectorXd t(n);
    const double first_sd = 0.1 + 0.02 * (trial % 40);  // from far better to far worse
    for (int i = 0; i < n; ++i) {
      t(i) = n01(rng);
      p(i, 0) = t(i) + first_sd * n01(rng);
      for (int c = 1; c < 4; ++c) p(i, c) = t(i) + 0.4 * n01(rng) + 0.05 * c;
    }
    const ShrunkStack s = ShrunkStackWeights(p, t, 5, 1.0, 2.0);
    ASSERT_GE(s.weights.minCoeff(), 0.0);
    ASSERT_NEAR(s.weights.sum(), 1.0, 1e-12);
    const double a = std::clamp(s.z - 1.0, 0.0, 1.0);
    ASSERT_NEAR(s.share, a, 1e-12) << "z " << s.z;
    Eigen::VectorXd expect = a * ConvexStackWeights(p, t);
    expect(0) += 1 - a;
    ASSERT_TRUE(s.weights.isApprox(expect, 1e-12)) << trial;
    full += a == 1;
    none += a == 0;
    between += a > 0 && a < 1;
  }
  EXPECT_GT(full, 10);  // every branch of the ramp is exercised
  EXPECT_GT(none, 10);
  EXPECT_GT(between, 3);
  // The first candidate exact: all weight stays on it (z = 0, the stack cannot beat it).
  Eigen::MatrixXd p(10, 2);
  Eigen::VectorXd t(10);
  for (int i = 0; i < 10; ++i) {
    t(i) = i;
    p(i, 0) = i;
    p(i, 1) = i + (i % 2 ? 1.0 : -1.0);
  }
  EXPECT_TRUE(ShrunkStackWeights(p, t, 5, 1.0, 2.0).weights.isApprox(Eigen::Vector2d(1, 0)));
  // The second exact and the first far off: all weight on the stack, which is the second.
  p.col(0).array() += 3.0 * Eigen::ArrayXd::LinSpaced(10, -1, 1).sin();
  p.col(1) = t;
  EXPECT_TRUE(ShrunkStackWeights(p, t, 5, 1.0, 2.0).weights.isApprox(Eigen::Vector2d(0, 1)));
  EXPECT_TRUE(ShrunkStackWeights(p, t, 5, 1e9, 2e9).weights.isApprox(Eigen::Vector2d(1, 0)));
  ExpectInputError([&] { ShrunkStackWeights(p, t, 1, 1.0, 2.0); }, "need >= 2");
}

TEST(FamilyStacking, CoverageScaleOnHandComputedCases) {
  // 20 rows, sd 1: |r| = 0.1, 0.2, ..., 2.0. +-1 sd must cover 14 rows (68.27 % of 20 -> 13.65):
  // the 14th ratio, 1.4; +-2 sd 20 rows (95.45 % -> 19.09): the 20th ratio / 2, 1.0.
  Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(20, 0.1, 2.0), sd = Eigen::VectorXd::Ones(20);
  EXPECT_NEAR(CoverageScale(r, sd), 1.4, 1e-12);
  r(19) = 4.0;  // one far residual: the +-2 sd rule takes over, 4.0 / 2
  EXPECT_NEAR(CoverageScale(r, sd), 2.0, 1e-12);
  sd *= 2.0;  // the scale is relative to the sd
  EXPECT_NEAR(CoverageScale(r, sd), 1.0, 1e-12);
  EXPECT_EQ(CoverageScale(Eigen::VectorXd::Zero(5), Eigen::VectorXd::Ones(5)), 0.25);  // clamped
  ExpectInputError([] { CoverageScale(Eigen::VectorXd::Ones(3), Eigen::VectorXd::Zero(3)); },
                   "every sd > 0");
}

TEST(FamilyStacking, StackSdScaleOnHandComputedCases) {
  // 20 rows, |r| = 0.1, 0.2, ..., 2.0. +-1 sd covers 14 rows (68.27 % of 20 -> 13.65) at the
  // 14th ratio; the scale only narrows (at most 1).
  Eigen::VectorXd r = Eigen::VectorXd::LinSpaced(20, 0.1, 2.0), sd = Eigen::VectorXd::Ones(20);
  EXPECT_EQ(StackSdScale(r, sd, 0), 1.0);  // 1.4 > 1
  EXPECT_NEAR(StackSdScale(r, 2.0 * sd, 0), 0.7, 1e-12);
  // Three far residuals (6.0): 90 % of 20 rows is 18 rows, the 18th ratio 6 / 4 = 1.5, halved
  // 0.75 > the +-1 sd factor 0.35; without the +-2 sd share, 0.35.
  r.tail(3).setConstant(6.0);
  EXPECT_NEAR(StackSdScale(r, 4.0 * sd, 0.9), 0.75, 1e-12);
  EXPECT_NEAR(StackSdScale(r, 4.0 * sd, 0), 0.35, 1e-12);
  EXPECT_EQ(StackSdScale(Eigen::VectorXd::Zero(5), Eigen::VectorXd::Ones(5), 0.9), 0.25);
  ExpectInputError([&] { StackSdScale(r, sd, 1.5); }, "must lie in [0, 1]");
  ExpectInputError([] { StackSdScale(Eigen::VectorXd::Ones(3), Eigen::VectorXd::Zero(3), 0); },
                   "every sd > 0");
}

TEST(FamilyStacking, ScaleSingleRescalesTheSdOfAWholeCandidateAndKeepsItsMean) {
  // stack_scale_single (the default): an output one candidate takes whole keeps no weights and
  // gets an sd_scale in [0.25, 1]; its means are those of the choice without the option, its sd
  // that sd times the scale, also after a round trip through the file. On 20-row power laws the
  // candidates' own calibration (every leave-one-out residual within +-2 sd) leaves room: some
  // scale is below 1.
  int narrowed = 0;
  for (unsigned seed = 7; seed < 12; ++seed) {
    const ProcessTable train = MakeTable(20, 0.03, seed), test = MakeTable(10, 0.0, seed + 50);
    ChoiceOptions plain, single;  // single: the default
    plain.stack_scale_single = false;
    const Choice a = ChooseFamily(train, plain), b = ChooseFamily(train, single);
    const Choice back = nlohmann::json(b).get<Choice>();
    const std::vector<FamilyPrediction> pa = PredictChoice(a, test.inputs),
                                        pb = PredictChoice(b, test.inputs),
                                        pback = PredictChoice(back, test.inputs);
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(a.weights[k].empty(), b.weights[k].empty()) << b.Describe();
      EXPECT_GE(b.sd_scale[k], 0.25);
      EXPECT_LE(b.sd_scale[k], 1.0);
      if (!a.weights[k].empty()) {
        EXPECT_EQ(a.sd_scale[k], b.sd_scale[k]);  // a combination: scaled either way
        continue;
      }
      EXPECT_EQ(a.sd_scale[k], 1.0);
      narrowed += b.sd_scale[k] < 0.999;
      for (std::size_t q = 0; q < test.inputs.size(); ++q) {
        EXPECT_EQ(pb[q].mean.ToArray()[k], pa[q].mean.ToArray()[k]);
        EXPECT_NEAR(pb[q].stddev.ToArray()[k], b.sd_scale[k] * pa[q].stddev.ToArray()[k],
                    1e-12 * pa[q].stddev.ToArray()[k]);
        EXPECT_EQ(pback[q].stddev.ToArray()[k], pb[q].stddev.ToArray()[k]);
      }
    }
  }
  EXPECT_GE(narrowed, 1) << "of the single-candidate outputs of 5 tables";
}

// A logistic step of 20 um in the direction of three inputs (the sixth attempt's reason for the
// network candidate: one tanh unit of it), settle time a power law, noise sd 0.5 um and 3 %.
ProcessTable LogisticTable(int rows, double noise, unsigned seed) {
  ProcessTable t = MakeTable(rows, 0.03, seed);
  std::mt19937_64 rng(seed + 1000);
  std::normal_distribution<double> n01;
  const double lo[5] = {60, 50, 6, 3, 150}, span[5] = {5, 50, 10, 7, 60};
  for (std::size_t q = 0; q < t.inputs.size(); ++q) {
    const std::array<double, 5> x = t.inputs[q].ToArray();
    double z = 0;
    for (int i : {0, 2, 3}) z += (x[i] - lo[i]) / span[i];
    t.targets[q].max_elongation_um = 10 + 20 / (1 + std::exp(-6 * (z - 1.5))) + noise * n01(rng);
  }
  return t;
}

TEST(FamilyCandidates, TheDefaultStackTakesTheNetworkForALogisticStep) {
  // The default candidates end with network-h2/identity; on 40-row logistic steps the default
  // choice gives it weight and beats the same choice without it on new rows (median over 5
  // tables).
  const auto names = ChoiceOptions::DefaultCandidates();
  ASSERT_EQ(names.back().Name(), "network-h2/identity");
  ChoiceOptions without;
  without.candidates.pop_back();
  std::vector<double> ratio;
  int network_weighted = 0;
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const ProcessTable train = LogisticTable(40, 0.5, seed), test = LogisticTable(200, 0, seed + 50);
    const Choice a = ChooseFamily(train, ChoiceOptions{}), b = ChooseFamily(train, without);
    for (std::size_t j = 0; j < a.models.size(); ++j)
      network_weighted += a.models[j].candidate.family == Family::kNetwork &&
                          (a.weights[0].empty() ? a.model_of_output[0] == static_cast<int>(j)
                                                : a.weights[0][j] > 0.5);
    double ea = 0, eb = 0;
    const auto pa = PredictChoice(a, test.inputs), pb = PredictChoice(b, test.inputs);
    for (std::size_t q = 0; q < test.inputs.size(); ++q) {
      ea += std::pow(pa[q].mean.max_elongation_um - test.targets[q].max_elongation_um, 2);
      eb += std::pow(pb[q].mean.max_elongation_um - test.targets[q].max_elongation_um, 2);
    }
    ratio.push_back(std::sqrt(ea / eb));
  }
  std::sort(ratio.begin(), ratio.end());
  EXPECT_GE(network_weighted, 3) << "of 5 tables";
  EXPECT_LT(ratio[2], 0.8) << "median test RMSE ratio with / without the network";
}

TEST(FamilyCandidates, NetworksSitOutOfLargeAndTinyTables) {
  // ChoiceOptions::network_max_rows: above it no network is fitted and rows_note says so; at 8
  // rows the networks sit out with the GPs (the linear fits alone, as before the network joined).
  ChoiceOptions o;
  o.network_max_rows = 30;
  const Choice large = ChooseFamily(MakeTable(31, 0.03, 3), o);
  for (const CvRow& r : large.table) EXPECT_NE(r.candidate.family, Family::kNetwork);
  EXPECT_NE(large.rows_note.find("above 30 rows the network candidates sit out"),
            std::string::npos)
      << large.rows_note;
  const Choice at = ChooseFamily(MakeTable(30, 0.03, 3), o);
  EXPECT_EQ(at.table.back().candidate.family, Family::kNetwork);
  EXPECT_TRUE(at.rows_note.empty()) << at.rows_note;
  const Choice tiny = ChooseFamily(MakeTable(8, 0.03, 3), ChoiceOptions{});
  for (const CvRow& r : tiny.table) EXPECT_EQ(r.candidate.family, Family::kLinear);
  EXPECT_NE(tiny.rows_note.find("and any network"), std::string::npos) << tiny.rows_note;
}

// Weight of linear/log (the power law) in output k of a choice: 1 or 0 for an unstacked output.
double PowerLawWeight(const Choice& c, int k) {
  if (c.weights[k].empty())
    return c.table[c.chosen[k]].candidate.Name() == "linear/log" ? 1.0 : 0.0;
  for (std::size_t j = 0; j < c.models.size(); ++j)
    if (c.models[j].candidate.Name() == "linear/log") return c.weights[k][j];
  return 0.0;
}

TEST(FamilyStacking, PowerLawTablesKeepThePowerLawUnderTheShrunkStack) {
  // 20-row power laws with 3 % noise: the shrunk stack (ChoiceOptions::stack with its gate and
  // shrinkage) leaves the power law's weight at 1 on at least 3 in 4 outputs and on more than
  // twice as many as the unshrunk stack of every candidate (the first attempt's failure on
  // power-law tables).
  ChoiceOptions shrunk, plain;
  shrunk.stack = plain.stack = true;
  plain.stack_full_se = -1;
  plain.stack_gate_se = 0;
  plain.lowest_gp = false;
  int whole_shrunk = 0, whole_plain = 0;
  for (unsigned seed = 1; seed <= 20; ++seed) {
    const ProcessTable t = MakeTable(20, 0.03, seed);
    const Choice a = ChooseFamily(t, shrunk), b = ChooseFamily(t, plain);
    for (int k = 0; k < 2; ++k) {
      EXPECT_GE(a.weights[k].empty() ? 0.0 : *std::min_element(a.weights[k].begin(),
                                                               a.weights[k].end()), 0.0);
      whole_shrunk += PowerLawWeight(a, k) >= 0.99;
      whole_plain += PowerLawWeight(b, k) >= 0.99;
    }
  }
  EXPECT_GE(whole_shrunk, 30) << "of 40 outputs (3 in 4); the unshrunk stack " << whole_plain;
  EXPECT_LT(2 * whole_plain, whole_shrunk);
}

TEST(FamilyStacking, StackedChoicePredictsTheWeightedMeanAndRoundTrips) {
  const ProcessTable train = MakeTable(20, 0.05, 31, true), test = MakeTable(30, 0.0, 32, true);
  ChoiceOptions o;
  o.candidates = {ParseCandidate("linear/log"), ParseCandidate("gp-matern52-constant/identity"),
                  ParseCandidate("gp-se-iso-constant/log")};
  o.stack = true;
  o.stack_full_se = -1;  // the unshrunk stack of every candidate, whose weights are spread
  o.stack_gate_se = 0;
  o.lowest_gp = false;
  const Choice c = ChooseFamily(train, o);
  ASSERT_GE(c.models.size(), 2u) << "no combination: the test would be moot; " << c.Describe();
  ASSERT_FALSE(c.weights[0].empty() && c.weights[1].empty()) << "no stack: " << c.Describe();
  const std::vector<FamilyPrediction> p = PredictChoice(c, test.inputs);
  for (int k = 0; k < 2; ++k) {
    if (c.weights[k].empty()) continue;  // one candidate alone (FamilyChoice tests)
    ASSERT_EQ(c.weights[k].size(), c.models.size()) << c.Describe();
    double sum = 0;
    for (const double w : c.weights[k]) sum += w;
    EXPECT_NEAR(sum, 1.0, 1e-12);
    for (std::size_t q = 0; q < test.inputs.size(); ++q) {
      double mean = 0, sd = 0;
      for (std::size_t j = 0; j < c.models.size(); ++j) {
        const FamilyPrediction pj = PredictFamily(c.models[j], {test.inputs[q]}).front();
        mean += c.weights[k][j] * pj.mean.ToArray()[k];
        sd += c.weights[k][j] * pj.stddev.ToArray()[k];
      }
      sd *= c.sd_scale[k];
      EXPECT_NEAR(p[q].mean.ToArray()[k], mean, 1e-9 * std::abs(mean));
      EXPECT_NEAR(p[q].stddev.ToArray()[k], sd, 1e-9 * sd);
    }
  }
  const Choice back = nlohmann::json(c).get<Choice>();
  const std::vector<FamilyPrediction> pb = PredictChoice(back, test.inputs);
  for (std::size_t q = 0; q < test.inputs.size(); ++q)
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(pb[q].mean.ToArray()[k], p[q].mean.ToArray()[k]);
      EXPECT_EQ(pb[q].stddev.ToArray()[k], p[q].stddev.ToArray()[k]);
    }
  nlohmann::json scale = c;
  scale["sd_scale"][0] = 5.0;
  ExpectInputError([&] { scale.get<Choice>(); }, "'sd_scale' of max_elongation_um");
  nlohmann::json bad = c;
  const int stacked = c.weights[0].empty() ? 1 : 0;
  bad["weights"][stacked][0] = bad["weights"][stacked][0].get<double>() + 0.5;
  ExpectInputError([&] { bad.get<Choice>(); }, "must sum to 1");
}

TEST(FamilyCandidates, NamesRoundTripAndBadInput) {
  for (const Candidate& c : ChoiceOptions::DefaultCandidates())
    EXPECT_EQ(ParseCandidate(c.Name()).Name(), c.Name());
  for (const char* n : {"network-h6/log", "network-h0/identity", "gp-se-linear/identity",
                        "gp-se-iso-constant/identity", "gp-matern52-iso-linear/log"})
    EXPECT_EQ(ParseCandidate(n).Name(), n);
  EXPECT_TRUE(ParseCandidate("gp-se-iso-constant/log").isotropic);
  EXPECT_FALSE(ParseCandidate("gp-se-constant/log").isotropic);
  ExpectInputError([] { ParseCandidate("gp-rbf/log"); }, "candidate 'gp-rbf/log'");
  ExpectInputError([] { ParseCandidate("network-h6"); }, "/identity or /log");
  ExpectInputError([] { ChooseFamily(MakeTable(3, 0.1, 1), {}); }, "at least 4");
  ProcessTable no_targets = MakeTable(10, 0.1, 1);
  no_targets.targets.clear();
  ExpectInputError([&] { ChooseFamily(no_targets, {}); }, "target columns");
}

// The GP slot from few_rows rows (gp_slot_large: the GP of highest BIC among all GPs) may go to a
// GP the gate dropped; with GP candidates only (`whirl train --family gp`) nothing was left, and
// the choice threw ("stacking weights: 70 x 0 predictions", or with the hard choice
// "one-standard-error rule: no candidates"). Now the first candidate, which the gate measured
// the others against, takes part alone: such an output is the first GP's, as if it were the
// only candidate (means and sd identical).
TEST(FamilyChoice, GpOnlyCandidatesKeepTheFirstWhenTheGateDropsTheSlotsGp) {
  const ProcessTable table = test::MakeFriedman23Table(70, 1);
  ChoiceOptions o, first_only;
  o.candidates = {ParseCandidate("gp-matern52-linear/log"),
                  ParseCandidate("gp-matern52-constant/identity")};
  first_only.candidates = {o.candidates.front()};
  ASSERT_GE(table.inputs.size(), static_cast<std::size_t>(o.few_rows));
  for (bool stack : {true, false}) {
    o.stack = first_only.stack = stack;
    const Choice c = ChooseFamily(table, o), alone = ChooseFamily(table, first_only);
    const std::vector<FamilyPrediction> p = PredictChoice(c, table.inputs),
                                        q = PredictChoice(alone, table.inputs);
    int first_alone = 0;
    for (int k = 0; k < 2; ++k) {
      if (c.chosen[k] != 0 || !c.weights[k].empty()) continue;
      ++first_alone;
      for (std::size_t r = 0; r < p.size(); ++r) {
        EXPECT_EQ(p[r].mean.ToArray()[k], q[r].mean.ToArray()[k]) << "stack " << stack;
        EXPECT_EQ(p[r].stddev.ToArray()[k], q[r].stddev.ToArray()[k]) << "stack " << stack;
      }
    }
    EXPECT_GE(first_alone, 1) << "stack " << stack << ": " << c.Describe();
  }
}

}  // namespace
}  // namespace whirl::family
