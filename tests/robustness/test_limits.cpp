// Physical and resource limits: each bad input of the sweep is an InputError naming
// the field and the rule, raised before any large allocation or long run; limits hold at their
// edges; metrics of valid extreme inputs stay finite; multi-file outputs are all-or-nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <functional>
#include <limits>
#include <random>
#include <string>

#include "compare/compare.h"
#include "lead/lead.h"
#include "lead/metrics.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/process.h"
#include "nn/model.h"
#include "sim/dataset.h"
#include "screw/screw.h"
#include "sim/simulator.h"
#include "support/expect_error.h"
#include "support/scratch_dir.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

const fs::path kSource(WHIRL_SOURCE_DIR);

// One folder per test (CTest runs the tests of this file in parallel processes).
fs::path Scratch(const std::string& name) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = info ? std::string(info->test_suite_name()) + "_" + info->name() : "";
  const fs::path d = whirl::test::ScratchDir() / ("whirl_test_limits_" + name + "_" + test);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(Limits, ProcessInputsAtTheEdgesAndBeyond) {
  ProcessInputs p{62, 80, 10, 3.7, 180};
  EXPECT_NO_THROW(CheckProcessInputs(p, "x"));
  p.diameter_mm = kMaxDiameterMm;
  EXPECT_NO_THROW(CheckProcessInputs(p, "x"));
  for (double bad : {-80.0, 0.0, std::nextafter(kMaxDiameterMm, 1e9), 1e308,
                     std::numeric_limits<double>::quiet_NaN()}) {
    p.diameter_mm = bad;
    const std::string e = ErrorOf([&] { CheckProcessInputs(p, "t.csv:7"); });
    EXPECT_NE(e.find("t.csv:7: diameter_mm"), std::string::npos) << bad << ": " << e;
    EXPECT_NE(e.find("(0, 500] mm"), std::string::npos) << e;
  }
  p.diameter_mm = 80;
  p.hardness_hrc = 70.5;
  EXPECT_NE(ErrorOf([&] { CheckProcessInputs(p, "x"); }).find("hardness_hrc"), std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              CheckFeatures({-1, 250}, "x");
            }).find("max_elongation_um"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              CheckFeatures({10, 1e7}, "x");
            }).find("settle_time_s"),
            std::string::npos);
}

TEST(Limits, ProcessTableRowNamesFileAndLine) {
  const fs::path d = Scratch("table");
  WriteFileAtomic(d / "t.csv",
                  "# comment\nhardness_hrc,diameter_mm,pitch_mm,raceway_radius_mm,"
                  "cutting_speed_m_min,max_elongation_um,settle_time_s\n"
                  "62,80,10,3.7,180,15,250\n62,1e308,10,3.7,180,15,250\n");
  const std::string e = ErrorOf([&] { ReadProcessTable(d / "t.csv", true); });
  EXPECT_NE(e.find("t.csv:4: diameter_mm = 1e+308"), std::string::npos) << e;
}

TEST(Limits, ScrewBlankLengthAndName) {
  screw::Screw s = screw::ReferenceScrew();
  s.length_mm = kMaxBlankLengthMm;
  EXPECT_NO_THROW(screw::ValidateScrew(s));
  for (double bad : {1e7, 1e9}) {
    s.length_mm = bad;
    EXPECT_NE(ErrorOf([&] { screw::ValidateScrew(s); }).find("at most 20000 mm"), std::string::npos);
  }
  const fs::path d = Scratch("screw");
  nlohmann::json j = screw::ReferenceScrew();
  j["name"] = std::string(screw::kMaxScrewNameLength + 1, 'n');
  WriteJsonFile(d / "s.json", j);
  EXPECT_NE(ErrorOf([&] { screw::ReadScrew(d / "s.json"); }).find("'name' has 201"),
            std::string::npos);
}

TEST(Limits, SimulationCellsAndStepsAreBoundedBeforeAllocating) {
  const screw::Screw s = screw::ReferenceScrew();  // 6000 mm blank
  sim::SimOptions o;
  o.duration_s = 10;
  for (double cell : {1e-300, 6000.0 / (sim::kMaxCells + 1), 2500.0, 1e300}) {
    o.cell_size_mm = cell;
    const std::string e = ErrorOf([&] { sim::Simulate(s, o); });
    EXPECT_NE(e.find("cells"), std::string::npos) << cell << ": " << e;
  }
  o.cell_size_mm = 2;
  o.time_step_s = 1e-6;
  o.duration_s = 100;  // 1e8 steps
  EXPECT_NE(ErrorOf([&] { sim::Simulate(s, o); }).find("steps"), std::string::npos);
  o.time_step_s = 1;
  o.cell_size_mm = 2000;  // exactly 3 cells: allowed
  EXPECT_NO_THROW(sim::Simulate(s, o));
}

// A copy of the shipped model's JSON with one change (the model is always shipped).
class ModelFile : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_TRUE(fs::exists(kSource / "models/default.json")) << "models/default.json not shipped";
    model_ = ReadJsonFile(kSource / "models/default.json");
    dir_ = Scratch("model");
  }
  std::string LoadError(const nlohmann::json& j) {
    WriteJsonFile(dir_ / "m.json", j);
    return ErrorOf([&] { nn::LoadModel(dir_ / "m.json"); });
  }
  nlohmann::json model_;
  fs::path dir_;
};

TEST_F(ModelFile, ShippedModelLoads) { EXPECT_EQ(LoadError(model_), ""); }

TEST_F(ModelFile, HugeLayerIsRefusedBeforeAllocating) {
  nlohmann::json j = model_;
  j["layer_sizes"] = {5, 2000000000, 2};
  EXPECT_NE(LoadError(j).find("layer_sizes[1]' must be a whole number in [1, 1000]"),
            std::string::npos);
  j["layer_sizes"] = {5, 1000, 1000, 1000, 2};  // 2e6 weights
  EXPECT_NE(LoadError(j).find("the limit is 1e+06"), std::string::npos);
  j["layer_sizes"] = {5, 2.5, 2};
  EXPECT_NE(LoadError(j).find("whole number"), std::string::npos);
}

TEST_F(ModelFile, EpochsOutOfIntRangeIsAnErrorNotACast) {
  for (double bad : {1e30, -1.0, 1.5, 1e6 + 1}) {
    nlohmann::json j = model_;
    j["training"]["options"]["epochs"] = bad;
    EXPECT_NE(LoadError(j).find("'epochs' must be a whole number"), std::string::npos) << bad;
  }
  nlohmann::json j = model_;
  ASSERT_FALSE(j["training"]["restart_runs"].empty());
  j["training"]["restart_runs"][0]["epochs"] = 1e30;
  EXPECT_NE(LoadError(j).find("epochs"), std::string::npos);
}

// Lead metrics over many random valid curves, from tiny to the limits: always finite.
TEST(Limits, LeadMetricsStayFiniteWithinTheLimits) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 200; ++trial) {
    lead::LeadDeviation lead;
    const double spacing = lead::kMinLeadSpacingMm * std::pow(1e9, u(rng));
    const double scale = std::pow(10.0, -320 + 326 * u(rng));  // subnormal .. the limit
    const int n = 2 + static_cast<int>(50 * u(rng));
    double x = -lead::kMaxLeadPositionMm * u(rng) * 0.5;
    for (int i = 0; i < n && x <= lead::kMaxLeadPositionMm; ++i, x += spacing) {
      lead.position_mm.push_back(x);
      lead.deviation_um.push_back(std::min(lead::kMaxLeadDeviationUm, scale) * (2 * u(rng) - 1));
    }
    if (lead.size() < 2) continue;
    lead::LeadMetricOptions o;
    o.lead_mm = u(rng) < 0.5 ? 10 : 0;
    const lead::LeadMetrics m = lead::ComputeLeadMetrics(lead, o);
    for (double v : {m.e_a_um, m.v_u_um, m.v_300_um, m.accumulated_1000_um, m.accumulated_total_um,
                     m.mean_line_slope_um_per_m, m.mean_line_offset_um})
      ASSERT_TRUE(std::isfinite(v)) << "trial " << trial << " spacing " << spacing;
  }
  lead::LeadDeviation far{{0, 1e307}, {0, 1}};
  EXPECT_NE(ErrorOf([&] { lead::ComputeLeadMetrics(far); }).find("position_mm"),
            std::string::npos);
}

TEST(Limits, ReductionAgainstAVanishingBaselineIsAbsentNotInfinite) {
  lead::LeadMetrics model, baseline;
  model.accumulated_1000_um = 1;
  baseline.accumulated_1000_um = 1e-310;  // subnormal: 1 / 1e-310 overflows
  baseline.e_a_um = 2;
  model.e_a_um = 1;
  const compare::MetricReductions r = compare::Reductions(model, baseline);
  EXPECT_FALSE(r.accumulated_1000_pct.has_value());
  ASSERT_TRUE(r.e_a_pct.has_value());
  EXPECT_DOUBLE_EQ(*r.e_a_pct, 50.0);
}

TEST(Limits, DatasetWithCurvesIsAllOrNothing) {
  const fs::path d = Scratch("dataset");
  sim::Dataset ds;
  ds.table.inputs = {{62, 80, 10, 3.7, 180}, {63, 70, 8, 3.5, 170}};
  ds.table.targets = {{15, 250}, {12, 240}};
  ds.curves = {{{0, 1, 2}, {0, 1, 2}}, {{0, 1, 2}, {0, 2, 3}}};
  fs::create_directories(d / "curves" / "row_0002.csv");  // the last curve cannot be written
  WriteFileAtomic(d / "t.csv", "previous");
  EXPECT_THROW(sim::WriteDataset(ds, d / "t.csv", d / "curves", " regenerate: test"), InputError);
  EXPECT_EQ(ReadTextFile(d / "t.csv"), "previous");
  EXPECT_FALSE(fs::exists(d / "curves" / "row_0001.csv"));
  fs::remove(d / "curves" / "row_0002.csv");
  sim::WriteDataset(ds, d / "t.csv", d / "curves", " regenerate: test");
  EXPECT_EQ(ReadProcessTable(d / "t.csv", true).inputs.size(), 2u);
  EXPECT_TRUE(fs::exists(d / "curves" / "row_0002.csv"));
  // A new curves folder is not left behind when the table cannot be written.
  EXPECT_THROW(sim::WriteDataset(ds, d / "nodir" / "t.csv", d / "new_curves", " r"), InputError);
  EXPECT_FALSE(fs::exists(d / "new_curves"));
}

}  // namespace
}  // namespace whirl
