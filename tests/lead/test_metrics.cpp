// Lead metrics against closed forms (ISO 3408-3 definitions), and the measured-lead reader.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "lead/metrics.h"
#include "core/error.h"
#include "support/scratch_dir.h"

namespace whirl::lead {
namespace {

constexpr double kPi = 3.14159265358979323846;

LeadDeviation Sampled(double length_mm, double step_mm, const std::function<double(double)>& f) {
  LeadDeviation lead;
  const int n = static_cast<int>(std::lround(length_mm / step_mm));
  for (int k = 0; k <= n; ++k) {
    const double x = k * step_mm;
    lead.position_mm.push_back(x);
    lead.deviation_um.push_back(f(x));
  }
  return lead;
}

TEST(LeadMetrics, PureLinearDeviationHasNoBandAndEaIsSlopeTimesLength) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> slope_dist(-0.05, 0.05), off_dist(-50, 50),
      len_dist(200, 6000);
  for (int trial = 0; trial < 50; ++trial) {
    const double slope = slope_dist(rng), offset = off_dist(rng), length = len_dist(rng);
    const LeadDeviation lead = Sampled(length, 1.0, [&](double x) { return offset + slope * x; });
    LeadMetricOptions options;
    options.lead_mm = 10;
    const LeadMetrics m = ComputeLeadMetrics(lead, options);
    const double l_u = lead.position_mm.back();
    EXPECT_NEAR(m.useful_travel_mm, l_u, 1e-9);
    EXPECT_NEAR(m.e_a_um, slope * l_u, 1e-9 * std::max(1.0, std::abs(slope * l_u)));
    EXPECT_NEAR(m.v_u_um, 0.0, 1e-9);
    EXPECT_NEAR(m.v_300_um, 0.0, 1e-9);
    ASSERT_TRUE(m.v_2pi_um.has_value());
    EXPECT_NEAR(*m.v_2pi_um, 0.0, 1e-9);
    // Accumulated error of a line: |slope| times the window (or the whole length).
    EXPECT_NEAR(m.accumulated_total_um, std::abs(slope) * l_u, 1e-9);
    EXPECT_NEAR(m.accumulated_1000_um, std::abs(slope) * std::min(1000.0, l_u), 1e-9);
  }
}

TEST(LeadMetrics, SineAboutALineMatchesClosedForms) {
  // d(x) = s x + A sin(2 pi x / lambda) over a whole number of periods: the least-squares line of
  // the sine over whole periods is not exactly 0 (x sin(..) has a non-zero integral), so check the
  // band widths on windows with lambda small against the length, where the tilt is negligible.
  const double amplitude = 3.0, lambda = 40.0, slope = 0.002, length = 4000.0;
  const LeadDeviation lead = Sampled(length, 0.25, [&](double x) {
    return slope * x + amplitude * std::sin(2 * kPi * x / lambda);
  });
  LeadMetricOptions options;
  options.lead_mm = 10;
  const LeadMetrics m = ComputeLeadMetrics(lead, options);
  // Fit of x sin(2 pi x/lambda) over [0, L] with L = N lambda: the LS slope error is
  // cov(x, A sin)/var(x) = (-A lambda L/(2 pi) / L - mean terms) ... small: A*lambda/(2 pi) /
  // (L^2/12) times L; bound it and check e_a.
  const double slope_error_bound = 12.0 * amplitude * lambda / (2 * kPi) / (length * length) * 2;
  EXPECT_NEAR(m.e_a_um, slope * length, slope_error_bound * length);
  // Band widths: 2 A up to the tilt left by the slope error over the window.
  EXPECT_NEAR(m.v_u_um, 2 * amplitude, slope_error_bound * length + 1e-3);
  EXPECT_NEAR(m.v_300_um, 2 * amplitude, slope_error_bound * 300 + 1e-3);
  // One revolution (10 mm) of a 40 mm sine: the largest range over a quarter period is A * sqrt(2)
  // (window centred on a zero crossing: sin(pi/4) - sin(-pi/4)).
  ASSERT_TRUE(m.v_2pi_um.has_value());
  EXPECT_NEAR(*m.v_2pi_um, amplitude * std::sqrt(2.0), 1e-3);
  // Raw deviation over 1000 mm windows: the line adds slope*1000 minus the best phase alignment;
  // bounded between slope*1000 and slope*1000 + 2A.
  EXPECT_GE(m.accumulated_1000_um, slope * 1000 - 1e-9);
  EXPECT_LE(m.accumulated_1000_um, slope * 1000 + 2 * amplitude + 1e-9);
}

TEST(LeadMetrics, PureSineWithoutTilt) {
  // A sine with a window of a full period: the band is exactly 2 A; with a window of half a period
  // centred on a crest: 2 A too (from -A to +A takes half a period).
  const double amplitude = 5.0, lambda = 600.0;
  const LeadDeviation lead =
      Sampled(6000.0, 0.5, [&](double x) { return amplitude * std::cos(2 * kPi * x / lambda); });
  LeadMetricOptions options;
  options.lead_mm = 0;  // v_2pi not evaluated
  const LeadMetrics m = ComputeLeadMetrics(lead, options);
  EXPECT_FALSE(m.v_2pi_um.has_value());
  EXPECT_NEAR(m.v_300_um, 2 * amplitude, 1e-2);  // 300 = half a period
  EXPECT_NEAR(m.accumulated_1000_um, 2 * amplitude, 1e-9);
  EXPECT_NEAR(m.accumulated_total_um, 2 * amplitude, 1e-9);
  // Shorter window w < lambda/2: the largest range is 2 A sin(pi w / lambda).
  EXPECT_NEAR(MaxWindowRange(lead.position_mm, lead.deviation_um, 100.0),
              2 * amplitude * std::sin(kPi * 100.0 / lambda), 1e-3);
}

TEST(LeadMetrics, MaxWindowRangeMatchesBruteForceOnRandomData) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<double> x, v;
    double pos = 0;
    const int n = 2 + static_cast<int>(u(rng) * 200);
    for (int i = 0; i < n; ++i) {
      pos += 0.1 + 10 * u(rng);
      x.push_back(pos);
      v.push_back(100 * (u(rng) - 0.5));
    }
    const double w = 1 + 300 * u(rng);
    double brute = 0;
    for (int i = 0; i < n; ++i) {
      double lo = v[i], hi = v[i];
      for (int j = i; j < n && x[j] <= x[i] + w; ++j) {
        lo = std::min(lo, v[j]);
        hi = std::max(hi, v[j]);
      }
      brute = std::max(brute, hi - lo);
    }
    EXPECT_DOUBLE_EQ(MaxWindowRange(x, v, w), brute) << "trial " << trial;
  }
}

TEST(LeadMetrics, EndMarginShortensTheUsefulTravel) {
  // Deviation steep only near the ends: a margin that cuts the ends removes it.
  const LeadDeviation lead = Sampled(
      1000.0, 1.0, [](double x) { return x < 100 ? (100 - x) : (x > 900 ? (x - 900) : 0.0); });
  LeadMetricOptions options;
  options.end_margin_mm = 100;
  const LeadMetrics m = ComputeLeadMetrics(lead, options);
  EXPECT_NEAR(m.useful_travel_mm, 800, 1e-9);
  EXPECT_NEAR(m.v_u_um, 0, 1e-12);
  EXPECT_NEAR(m.accumulated_total_um, 0, 1e-12);
  options.end_margin_mm = 500;
  EXPECT_THROW(ComputeLeadMetrics(lead, options), InputError);
  options.end_margin_mm = -1;
  EXPECT_THROW(ComputeLeadMetrics(lead, options), InputError);
}

TEST(LeadMetrics, MetricsAreOffsetFreeAndSignSymmetric) {
  std::mt19937 rng(3);
  std::normal_distribution<double> g(0, 5);
  LeadDeviation lead = Sampled(3000, 2.0, [&](double) { return g(rng); });
  LeadMetricOptions options;
  options.lead_mm = 16;
  const LeadMetrics a = ComputeLeadMetrics(lead, options);
  LeadDeviation shifted = lead, flipped = lead;
  for (auto& d : shifted.deviation_um) d += 123.0;
  for (auto& d : flipped.deviation_um) d = -d;
  for (const LeadDeviation* other : {&shifted, &flipped}) {
    const LeadMetrics b = ComputeLeadMetrics(*other, options);
    EXPECT_NEAR(std::abs(a.e_a_um), std::abs(b.e_a_um), 1e-9);
    EXPECT_NEAR(a.v_u_um, b.v_u_um, 1e-9);
    EXPECT_NEAR(a.v_300_um, b.v_300_um, 1e-9);
    EXPECT_NEAR(*a.v_2pi_um, *b.v_2pi_um, 1e-9);
    EXPECT_NEAR(a.accumulated_1000_um, b.accumulated_1000_um, 1e-9);
    EXPECT_NEAR(a.accumulated_total_um, b.accumulated_total_um, 1e-9);
  }
  // Ordering invariants of band widths.
  EXPECT_LE(*a.v_2pi_um, a.v_300_um + 1e-12);
  EXPECT_LE(a.v_300_um, a.v_u_um + 1e-12);
  EXPECT_LE(a.accumulated_1000_um, a.accumulated_total_um + 1e-12);
}

TEST(LeadMetrics, CoarseSamplesLeaveV2piUnevaluated) {
  const LeadDeviation lead = Sampled(1000, 10.0, [](double x) { return 0.01 * x; });
  LeadMetricOptions options;
  options.lead_mm = 10;
  EXPECT_FALSE(ComputeLeadMetrics(lead, options).v_2pi_um.has_value());
}

class LeadFile : public ::testing::Test {
 protected:
  std::filesystem::path dir_ = whirl::test::ScratchDir() / "whirl_lead_file";
  void SetUp() override { std::filesystem::create_directories(dir_); }
  std::filesystem::path Write(const std::string& name, const std::string& text) {
    const auto p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }
};

TEST_F(LeadFile, RoundTripKeepsEveryValue) {
  LeadDeviation lead = Sampled(100, 0.1, [](double x) { return std::sin(x) / 3.0; });
  const auto p = dir_ / "round.csv";
  WriteLeadDeviation(p, lead, {"provenance: test"});
  const LeadDeviation back = ReadLeadDeviation(p);
  ASSERT_EQ(back.size(), lead.size());
  for (std::size_t i = 0; i < lead.size(); ++i) {
    EXPECT_EQ(back.position_mm[i], lead.position_mm[i]);
    EXPECT_EQ(back.deviation_um[i], lead.deviation_um[i]);
  }
}

TEST_F(LeadFile, BadFilesNameFileAndLine) {
  const auto decreasing = Write("dec.csv", "# c\nposition_mm,deviation_um\n0,1\n5,2\n5,3\n");
  try {
    ReadLeadDeviation(decreasing);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("dec.csv:5"), std::string::npos) << msg;
    EXPECT_NE(msg.find("increase strictly"), std::string::npos) << msg;
  }
  EXPECT_THROW(ReadLeadDeviation(Write("one.csv", "position_mm,deviation_um\n0,1\n")), InputError);
  EXPECT_THROW(ReadLeadDeviation(Write("col.csv", "position_mm,dev_um\n0,1\n1,2\n")), InputError);
  EXPECT_THROW(ReadLeadDeviation(Write("nan.csv", "position_mm,deviation_um\n0,1\n1,nan\n")),
               InputError);
  EXPECT_THROW(ReadLeadDeviation(dir_ / "missing.csv"), InputError);
}

}  // namespace
}  // namespace whirl::lead
