// Drift inputs that used to produce nonsense or an anonymous failure: dead and duplicate sensors
// (named, left out, all-dead refused), model files with out-of-range numbers, run files with a
// byte-order mark or hexadecimal numbers, a non-finite split threshold.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "drift/fit.h"
#include "drift/model.h"
#include "drift/selection.h"
#include "synthetic.h"

namespace whirl::drift {
namespace {

// A planted run (3 groups of 2 sensors) with two more columns: `dead_C`, constant, and
// `copy_C` = 2 g0s0 - 15 (the same series up to scale and offset), inserted before g1s0.
Run WithDeadAndCopy(unsigned seed, double dead_level = 21.5) {
  Run r = synth::PlantedRun(seed, 3, 2, {1.0, -2.0, 0.5});
  const Eigen::Index n = r.temperature_C.rows();
  Eigen::MatrixXd t(n, r.temperature_C.cols() + 2);
  t << r.temperature_C.leftCols(2), Eigen::VectorXd::Constant(n, dead_level),
      2 * r.temperature_C.col(0).array() - 15, r.temperature_C.rightCols(4);
  r.temperature_C = t;
  r.sensor_names.insert(r.sensor_names.begin() + 2, {"dead_C", "copy_C"});
  return r;
}

bool Has(const std::vector<std::string>& v, const std::string& s) {
  return std::find(v.begin(), v.end(), s) != v.end();
}

std::string Joined(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

TEST(StuckSensors, DeadAndDuplicateAreNamedAndLeftOutOfTheSelection) {
  // Two runs: the dead sensor sits at another level in each (its rises are still 0).
  const std::vector<drift::Run> runs{WithDeadAndCopy(1, 21.5), WithDeadAndCopy(2, 23.0)};
  for (const ClassCountRule rule :
       {ClassCountRule::kLargestMargin, ClassCountRule::kFewestSignificant}) {
    SelectionOptions o;
    o.rule = rule;
    const Selection s = SelectSensors(runs, "e_um", o);
    EXPECT_FALSE(Has(s.sensor_names, "dead_C"));
    EXPECT_FALSE(Has(s.sensor_names, "copy_C"));
    EXPECT_EQ(s.sensor_names.size(), 6u);
    ASSERT_EQ(s.left_out.size(), 2u) << Joined(s.left_out);
    EXPECT_EQ(s.left_out[0].rfind("dead_C is dead", 0), 0u) << s.left_out[0];
    EXPECT_NE(s.left_out[0].find("planted_1, planted_2"), std::string::npos) << s.left_out[0];
    EXPECT_EQ(s.left_out[1].rfind("copy_C moves exactly as g0s0_C", 0), 0u) << s.left_out[1];
  }
}

TEST(StuckSensors, ASensorThatMovesInOneRunIsKept) {
  drift::Run moving = synth::PlantedRun(3, 2, 2, {1.0, -1.0});
  drift::Run stuck = synth::PlantedRun(4, 2, 2, {1.0, -1.0});
  stuck.temperature_C.col(1).setConstant(20.0);
  const Selection s = SelectSensors({moving, stuck}, "e_um");
  EXPECT_TRUE(s.left_out.empty()) << Joined(s.left_out);
  EXPECT_EQ(s.sensor_names.size(), 4u);
}

TEST(StuckSensors, ScreenKeepsNearlyEqualSeriesAndNamesEveryRule) {
  const drift::Run r = synth::PlantedRun(5, 1, 2, {1.0});
  Eigen::MatrixXd rises(r.samples(), 3);
  rises.col(0) = r.Rises().col(0);
  rises.col(1) = rises.col(0);
  rises(10, 1) += 1e-3;                // one reading differs by 1 mK: a different sensor
  rises.col(2) = -0.5 * rises.col(0);  // anti-correlated copy: |r| = 1
  const SensorScreen s = ScreenSensors(rises, {"a_C", "b_C", "c_C"}, "r.csv");
  EXPECT_EQ(s.usable, (std::vector<int>{0, 1}));
  ASSERT_EQ(s.left_out.size(), 1u);
  EXPECT_EQ(s.left_out[0].rfind("c_C moves exactly as a_C in r.csv", 0), 0u) << s.left_out[0];
}

TEST(StuckSensors, AllDeadIsAnErrorNamingTheFiles) {
  drift::Run r = synth::PlantedRun(6, 4, 4, {1, 1, 1, 1});
  for (Eigen::Index j = 0; j < r.temperature_C.cols(); ++j)
    r.temperature_C.col(j).setConstant(20.0 + static_cast<double>(j));
  try {
    SelectSensors({r}, "e_um");
    FAIL() << "all-dead input was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("planted_6: no usable temperature sensor"),
              std::string::npos)
        << e.what();
  }
  FitOptions o;
  o.sensors = {"g0s0_C", "g1s1_C"};
  EXPECT_THROW(FitDriftModel({r}, "e_um", o), InputError);
}

// The regression used to die with "rank 3 of 4" naming neither the file nor a sensor.
TEST(StuckSensors, FitLeavesThemOutOfGivenAndSelectedSensors) {
  const drift::Run r = WithDeadAndCopy(7);
  FitOptions given;
  given.sensors = {"dead_C", "g0s0_C", "copy_C", "g2s1_C"};
  const FitReport a = FitDriftModel({r}, "e_um", given);
  EXPECT_EQ(a.model.sensors, (std::vector<std::string>{"g0s0_C", "g2s1_C"}));
  EXPECT_EQ(a.warnings.size(), 2u) << Joined(a.warnings);
  FitOptions selected;
  selected.selection.rule = ClassCountRule::kLargestMargin;
  const FitReport b = FitDriftModel({r}, "e_um", selected);
  EXPECT_FALSE(Has(b.model.sensors, "dead_C"));
  EXPECT_FALSE(Has(b.model.sensors, "copy_C"));
  EXPECT_EQ(b.warnings.size(), 2u) << Joined(b.warnings);
}

TEST(StuckSensors, ARemainingCollinearityNamesTheFileAndTheFeatures) {
  drift::Run r = synth::PlantedRun(8, 3, 1, {1.0, -1.0, 0.5});
  r.temperature_C.col(2) = r.temperature_C.col(0) + r.temperature_C.col(1);  // c = a + b
  FitOptions o;
  o.sensors = r.sensor_names;
  try {
    FitDriftModel({r}, "e_um", o);
    FAIL() << "a collinear set was fitted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.rfind("planted_8: model of e_um on g0s0_C, g1s0_C, g2s0_C: regression:", 0), 0u)
        << m;
  }
}

TEST(DriftInputs, ModelFileNumbersAreRangeChecked) {
  const drift::Run run = synth::LaggedRun();  // the lag search keeps tau = 40
  FitOptions o;
  o.kind = ModelKind::kDynamic;
  o.sensors = {"g0s0_C", "g2s0_C"};
  o.tau_grid = {10, 40, 160};
  o.max_lags = 1;
  const nlohmann::json good = FitDriftModel({run}, "e_um", o).model;
  ASSERT_NO_THROW(good.get<DriftModel>());
  auto error_of = [&](const char* key, const nlohmann::json& value) {
    nlohmann::json j = good;
    j[key] = value;
    try {
      (void)j.get<DriftModel>();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("residual_std_um", 1e308).find("residual_std_um = 1e+308"), std::string::npos);
  EXPECT_NE(error_of("residual_std_um", -1e308).find("residual_std_um = -1e+308"),
            std::string::npos);
  EXPECT_NE(error_of("residual_std_um", -1).find("residual_std_um = -1"), std::string::npos);
  EXPECT_NE(error_of("r_squared", 2).find("r_squared = 2"), std::string::npos);
  EXPECT_NE(error_of("schema_version", 1.5).find("schema_version"), std::string::npos);
  EXPECT_NE(error_of("schema_version", 99).find("schema_version"), std::string::npos);
  nlohmann::json lag = good;
  ASSERT_FALSE(lag["time_constants"].empty());
  lag["time_constants"][0] = 1e308;
  EXPECT_THROW(lag.get<DriftModel>(), InputError);
}

TEST(DriftInputs, RunFileByteOrderMarkAndHexadecimalNumbers) {
  const drift::Run r =
      ParseRun("\xEF\xBB\xBFtime_min,a_C,e_um\n0,20,0\n1.5,21,1\n", "r.csv", RunState::kIdle);
  EXPECT_FALSE(r.time_from_index) << "the mark hid the time column";
  EXPECT_EQ(r.time_min, (std::vector<double>{0, 1.5}));
  const drift::Run c =
      ParseRun("\xEF\xBB\xBF# logger export\ntime_s,a_C\n0,20\n60,21\n", "r.csv", RunState::kIdle);
  EXPECT_EQ(c.time_min, (std::vector<double>{0, 1}));
  for (const char* text : {"time_min,a_C\n0,20\n0x1p0,21\n", "time_min,a_C\n0,20\n1,0x15\n"})
    EXPECT_THROW(ParseRun(text, "r.csv", RunState::kIdle), InputError) << text;
  EXPECT_TRUE(ParseRun("time_min,a_C\n0,20\nNaN,21\n", "r.csv", RunState::kIdle).time_from_index);
}

TEST(DriftInputs, SplitThresholdMustBeFinite) {
  const drift::Run r = ParseRun("time_min,a_C,spindle_rpm\n0,20,0\n1,21,1000\n2,21,0\n3,22,1000\n",
                                "r.csv", RunState::kIdle);
  EXPECT_EQ(SplitAtStarts(r, "spindle_rpm", 0).size(), 2u);
  EXPECT_THROW(SplitAtStarts(r, "spindle_rpm", NAN), InputError);
  EXPECT_THROW(SplitAtStarts(r, "spindle_rpm", INFINITY), InputError);
}

}  // namespace
}  // namespace whirl::drift
