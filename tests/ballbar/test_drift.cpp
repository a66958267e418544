// Drift from ball-bar readings (eq. 18) against the simulated warm-up's planted truth, its
// uncertainty, the bar-expansion correction, averaging, files and SD43900.
#include <gtest/gtest.h>

#include "support/expect_error.h"

#include <cmath>

#include "ballbar/drift.h"
#include "synthetic/ballbar.h"
#include "core/error.h"
#include "support/eigen_near.h"

namespace whirl::ballbar {
namespace {

using Eigen::Vector3d;

// sd of one simulated reading: noise 0.1 um and rounding to 0.1 um (uniform, sd 0.1/sqrt(12)).
const double kReadingSdUm = std::sqrt(0.01 + 0.01 / 12);

TEST(Simulation, PlantedDriftIsInTheIssuesRanges) {
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    synthetic::WarmupOptions o;
    o.seed = seed;
    const synthetic::WarmupSimulation s = synthetic::SimulateWarmup(o);
    for (int a = 0; a < 2; ++a) {
      EXPECT_GE(std::abs(s.final_drift_um(a)), 2);
      EXPECT_LE(std::abs(s.final_drift_um(a)), 10);
    }
    EXPECT_GE(-s.final_drift_um.z(), 20);
    EXPECT_LE(-s.final_drift_um.z(), 60);
    EXPECT_EQ(s.block_time_min.size(), 17u);  // 0, 15, ..., 240 min
  }
}

TEST(Drift, RecoversThePlantedDriftWithinItsStatedUncertainty) {
  // Normalized errors (estimate - truth) / sd over 10 seeds x 16 warm blocks x 3 axes: with the
  // reading sd known and alpha exact, they must look like N(0, 1).
  std::vector<double> z;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    synthetic::WarmupOptions so;
    so.seed = seed;
    const synthetic::WarmupSimulation s = synthetic::SimulateWarmup(so);
    DriftOptions o;
    o.bar_sd_um = kReadingSdUm;
    o.bar_alpha_sd_per_K = 0;
    const DriftResult r = ComputeDrift(s.readings, s.pivots_mm, o);
    ASSERT_EQ(r.blocks.size(), s.truth_um.size());
    for (std::size_t b = 1; b < r.blocks.size(); ++b) {
      EXPECT_NEAR(r.blocks[b].time_min, s.block_time_min[b], 1e-9);
      for (int a = 0; a < 3; ++a)
        z.push_back((r.blocks[b].drift_um(a) - s.truth_um[b](a)) / r.blocks[b].drift_sd_um(a));
    }
  }
  double ss = 0, worst = 0;
  int within2 = 0;
  for (double v : z) {
    ss += v * v;
    worst = std::max(worst, std::abs(v));
    within2 += std::abs(v) <= 2;
  }
  const double rms = std::sqrt(ss / z.size());
  EXPECT_GT(rms, 0.8) << "stated uncertainty too large";
  EXPECT_LT(rms, 1.2) << "stated uncertainty too small";
  EXPECT_GT(within2, 0.92 * z.size());
  EXPECT_LT(worst, 4.5);
}

TEST(Drift, DefaultOptionsAreConservativeOnTheDemo) {
  // The defaults (sd pooled from repeats, alpha sd 1e-6 /K): every block within 3 sd.
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup({});
  const DriftResult r = ComputeDrift(s.readings, s.pivots_mm);
  ASSERT_TRUE(r.pooled_bar_sd_um.has_value());
  EXPECT_GE(*r.pooled_bar_sd_um, 0.5 * kReadingSdUm);
  for (std::size_t b = 1; b < r.blocks.size(); ++b)
    for (int a = 0; a < 3; ++a)
      EXPECT_LE(std::abs(r.blocks[b].drift_um(a) - s.truth_um[b](a)),
                3 * r.blocks[b].drift_sd_um(a))
          << "block " << b << " axis " << a;
  EXPECT_EQ(r.placement.rating, "good");
}

TEST(Drift, BarExpansionCorrectionRemovesABiasOfSeveralSd) {
  synthetic::WarmupOptions so;
  so.bar_rise_K = 3;
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup(so);
  DriftOptions o;
  o.bar_sd_um = kReadingSdUm;
  o.bar_alpha_sd_per_K = 0;
  const DriftResult good = ComputeDrift(s.readings, s.pivots_mm, o);
  o.correct_bar_temperature = false;
  const DriftResult raw = ComputeDrift(s.readings, s.pivots_mm, o);
  EXPECT_FALSE(raw.bar_temperature_corrected);
  const auto& g = good.blocks.back();
  const auto& w = raw.blocks.back();
  const Vector3d truth = s.truth_um.back();
  // A bar 3 K warmer reads about 150 mm * 12e-6 * 3 K = 5.4 um short on every pivot: the ball
  // appears lower. Corrected: within 3 sd; uncorrected: off by more than 10 sd in Z.
  EXPECT_LE(std::abs(g.drift_um.z() - truth.z()), 3 * g.drift_sd_um.z());
  EXPECT_GT(std::abs(w.drift_um.z() - truth.z()), 10 * w.drift_sd_um.z());
  EXPECT_LT(w.drift_um.z(), truth.z());
}

TEST(Drift, AlphaUncertaintyEntersTheSd) {
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup({});
  DriftOptions o;
  o.bar_sd_um = kReadingSdUm;
  o.bar_alpha_sd_per_K = 0;
  const DriftResult a0 = ComputeDrift(s.readings, s.pivots_mm, o);
  o.bar_alpha_sd_per_K = 2e-6;
  const DriftResult a2 = ComputeDrift(s.readings, s.pivots_mm, o);
  // Last block: bar ~1.5 K warmer, L ~150 mm: alpha sd 2e-6 -> ~0.45 um per length, common to
  // the three bars, i.e. mostly along the bars' mean direction (Z).
  const double extra = std::sqrt(std::pow(a2.blocks.back().drift_sd_um.z(), 2) -
                                 std::pow(a0.blocks.back().drift_sd_um.z(), 2));
  EXPECT_GT(extra, 0.3);
  EXPECT_LT(extra, 1.0);
}

TEST(Drift, LengthAveragingAgreesWithTheTripletAveragingOfEq18) {
  // Block 1 of the demo has two readings per pivot: eq. 18's mean of the two trilaterated
  // triplets. Adding a third pivot-1 reading equal to the mean of its two keeps every pivot's mean
  // length but makes the counts unequal, so the block averages lengths instead. The two agree to
  // second order in the noise (sigma^2 / L ~ 1e-7 um here).
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup({});
  Readings r = s.readings;
  Readings extra = r;
  ASSERT_EQ(r.rows[6].pivot, 1);
  ASSERT_EQ(r.rows[11].pivot, 1);
  Reading mean = r.rows[11];
  mean.length_mm = 0.5 * (r.rows[6].length_mm + r.rows[11].length_mm);
  mean.bar_temperature_C = 0.5 * (*r.rows[6].bar_temperature_C + *r.rows[11].bar_temperature_C);
  extra.rows.insert(extra.rows.begin() + 12, mean);
  DriftOptions o;
  o.correct_bar_temperature = false;  // the mean of corrected lengths is then the mean length
  const DriftResult a = ComputeDrift(r, s.pivots_mm, o);
  const DriftResult b = ComputeDrift(extra, s.pivots_mm, o);
  EXPECT_EQ(a.blocks[1].averaging, "positions");
  EXPECT_EQ(b.blocks[1].averaging, "lengths");
  EXPECT_EQ(b.blocks[1].readings[0], 3);
  EXPECT_TRUE(test::AllNear(a.blocks[1].drift_um, b.blocks[1].drift_um, 0, 1e-5));
  // And the pair is not trivially equal: the triplets themselves differ by the noise.
  EXPECT_NE(a.blocks[1].drift_um, b.blocks[1].drift_um);
}

TEST(Drift, NoiseFreeReadingsGiveTheTruthExactly) {
  synthetic::WarmupOptions clean;
  clean.bar_noise_sd_um = 0;
  clean.resolution_um = 0;
  const synthetic::WarmupSimulation c = synthetic::SimulateWarmup(clean);
  DriftOptions o;
  o.bar_sd_um = 0.1;
  const DriftResult r = ComputeDrift(c.readings, c.pivots_mm, o);
  // Left: the temperature's 0.01 K recording (0.01 K x 12e-6 x 150 mm = 0.02 um) and the drift's
  // curvature within a block; the palindromic order cancels its slope.
  for (std::size_t b = 0; b < r.blocks.size(); ++b)
    EXPECT_TRUE(test::AllNear(r.blocks[b].drift_um, c.truth_um[b], 0, 0.03)) << "block " << b;
}

TEST(Drift, Sd43900IsMinusTheDriftInMmWithSubtract) {
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup({});
  DriftOptions o;
  const DriftResult sub = ComputeDrift(s.readings, s.pivots_mm, o);
  EXPECT_TRUE(test::AllNear(sub.sd43900_mm, -sub.blocks.back().drift_um / 1000, 1e-15));
  o.sign = interp::SignConvention::kAdd;
  const DriftResult add = ComputeDrift(s.readings, s.pivots_mm, o);
  EXPECT_TRUE(test::AllNear(add.sd43900_mm, add.blocks.back().drift_um / 1000, 1e-15));
  EXPECT_LT(add.sd43900_mm.z(), 0);  // the spindle grew towards the table
}

TEST(Drift, RunFileHasTheDriftModulesFormat) {
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup({});
  const DriftResult r = ComputeDrift(s.readings, s.pivots_mm);
  const std::string csv = FormatDriftCsv(r, {"provenance"});
  EXPECT_EQ(csv.rfind("# provenance\ntime_min,drift_x_um,drift_y_um,drift_z_um\n", 0), 0u) << csv;
  // Round trip through the readings format too.
  const Readings back = ParseReadings(FormatReadings(s.readings), "x.csv");
  ASSERT_EQ(back.rows.size(), s.readings.rows.size());
  EXPECT_EQ(back.rows[5].length_mm, s.readings.rows[5].length_mm);
}

TEST(Drift, BlocksSplitWhereReadingsAreMoreThanTheGapApart) {
  // Same readings, stamped either per reading (0.25 min apart) or all at the block's time: the
  // same blocks and drift; a gap below the within-block spacing splits them (and then fails).
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup({});
  Readings same_time = s.readings;
  for (std::size_t i = 0; i < same_time.rows.size(); ++i)
    same_time.rows[i].time_min = s.readings.rows[i - i % 6].time_min;
  const DriftResult a = ComputeDrift(s.readings, s.pivots_mm);
  const DriftResult b = ComputeDrift(same_time, s.pivots_mm);
  ASSERT_EQ(a.blocks.size(), b.blocks.size());
  EXPECT_TRUE(test::AllNear(a.blocks.back().drift_um, b.blocks.back().drift_um, 0, 1e-12));
  EXPECT_NEAR(b.blocks[2].time_min, 30, 1e-12);
  DriftOptions o;
  o.block_gap_min = 0.2;
  EXPECT_THROW(ComputeDrift(s.readings, s.pivots_mm, o), InputError);
}

TEST(Drift, BadReadingsNameFileLineAndRule) {
  const std::string h = "time_min,pivot,length_mm\n";
  ExpectInputError([&] { ParseReadings(h + "0,4,150\n", "r.csv"); }, "r.csv:2: column 'pivot'");
  ExpectInputError([&] { ParseReadings(h + "0,1,-1\n", "r.csv"); }, "column 'length_mm'");
  ExpectInputError([&] { ParseReadings(h + "5,1,150\n4,2,150\n", "r.csv"); }, "r.csv:3");
  ExpectInputError([&] { ParseReadings("time_min,pivot,length_mm,foo\n0,1,1,1\n", "r.csv"); },
                   "unknown column 'foo'");
  ExpectInputError([&] { ParseReadings("time_min,pivot\n0,1\n", "r.csv"); }, "length_mm");
  ExpectInputError(
      [&] { ParseReadings("time_min,pivot,length_mm,bar_temperature_C\n0,1,150,99\n", "r.csv"); },
      "bar_temperature_C");
  const synthetic::WarmupSimulation s = synthetic::SimulateWarmup({});
  ExpectInputError(
      [&] { ComputeDrift(ParseReadings(h + "0,1,150\n0,2,150\n", "r.csv"), s.pivots_mm); },
      "no reading of pivot 3");
  // Lengths that cannot meet: the error names the block's lines and the equation.
  ExpectInputError(
      [&] {
        ComputeDrift(ParseReadings(h + "0,1,150\n0,2,150\n0,3,900\n", "r.csv"), s.pivots_mm, [] {
          DriftOptions o;
          o.bar_sd_um = 0.1;
          return o;
        }());
      },
      "r.csv:2-4");
  // Without repeats and without a given sd the noise is unknown.
  Readings once = s.readings;
  once.rows.resize(3);
  ExpectInputError([&] { ComputeDrift(once, s.pivots_mm); }, "--bar-sd-um");
}

TEST(Drift, BadPivotsFileIsRejected) {
  nlohmann::json j = PivotsToJson({Vector3d(0, 0, 0), Vector3d(1, 0, 0), Vector3d(0, 1, 0)});
  EXPECT_NO_THROW(PivotsFromJson(j, "p.json"));
  auto bad = j;
  bad["schema"] = "other";
  ExpectInputError([&] { PivotsFromJson(bad, "p.json"); }, "schema");
  bad = j;
  bad["pivots_mm"].erase(2);
  ExpectInputError([&] { PivotsFromJson(bad, "p.json"); }, "three");
  bad = j;
  bad["pivots"] = 1;
  ExpectInputError([&] { PivotsFromJson(bad, "p.json"); }, "pivots");
  bad = j;
  bad["pivots_mm"][1][2] = "x";
  ExpectInputError([&] { PivotsFromJson(bad, "p.json"); }, "pivots_mm[1][2]");
}

}  // namespace
}  // namespace whirl::ballbar
