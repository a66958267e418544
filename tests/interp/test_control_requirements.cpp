// What the control must provide (interp/control_requirements.h), built from the plan's and the
// drift action's data: the thresholds equal those the programs' own headers state (read here
// independently from the text), and two programs run together list each machine datum once with
// the threshold both need (the largest $AC_PARAM index, the sum of their synchronized actions,
// the union of the MD32750 bits, the sum of the slopes).
#include <gtest/gtest.h>

#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "drift/model.h"
#include "fit/arctan_curve.h"
#include "interp/control_requirements.h"
#include "interp/drift_action.h"
#include "interp/sinumerik.h"

namespace whirl::interp {
namespace {

// The number after `pattern` (a regex with one group) on the header line that starts with
// "; requires" and names `datum`; NaN when there is none.
double HeaderThreshold(const std::string& nc, const std::string& datum,
                       const std::string& pattern) {
  std::istringstream in(nc);
  for (std::string line; std::getline(in, line) && line.rfind(";", 0) == 0;) {
    if (line.rfind("; requires", 0) != 0) continue;
    const std::size_t at = line.find(datum);
    if (at == std::string::npos) continue;
    std::smatch m;
    const std::string rest = line.substr(at);
    if (std::regex_search(rest, m, std::regex(pattern))) return std::stod(m[1]);
  }
  return std::nan("");
}

const ControlRequirement* Find(const std::vector<ControlRequirement>& r, const std::string& datum) {
  for (const ControlRequirement& x : r)
    if (x.datum.rfind(datum, 0) == 0) return &x;
  return nullptr;
}

int Count(const std::vector<ControlRequirement>& r, const std::string& datum) {
  int n = 0;
  for (const ControlRequirement& x : r) n += x.datum.rfind(datum, 0) == 0;
  return n;
}

// Two sensors, one lag: the drift action's offset model, and its slope model.
drift::DriftModel RequirementsModel(const char* column, double scale) {
  drift::DriftModel m;
  m.kind = drift::ModelKind::kDynamic;
  m.error_column = column;
  m.sensors = {"t1_C", "t2_C"};
  m.reference_C = Eigen::Vector2d(24.5, 26.25);
  m.time_constants = {10.0};
  for (const auto& s : m.sensors) m.features.push_back({s, 0.0}), m.features.push_back({s, 10.0});
  m.feature_min = Eigen::VectorXd::Constant(4, -5);
  m.feature_max = Eigen::VectorXd::Constant(4, 5);
  m.linear.coefficients = scale * Eigen::VectorXd::LinSpaced(5, 0.5, 2.5);
  m.linear.covariance = Eigen::MatrixXd::Identity(5, 5) * 0.01;
  m.Validate();
  return m;
}

DriftActionOptions RequirementsDriftOptions() {
  DriftActionOptions o;
  o.error_direction = -1;
  o.sync_id_first = 200;
  o.sync_id_last = 240;
  o.param_first = 100;
  o.save_r_first = 80;
  o.workpiece_k0_param = 99;
  o.workpiece_slope_param = 97;
  o.has_slope = true;
  o.slope_fixed_end_mm = 5587.5;
  o.slope_growth_direction = -1;
  o.reference = DriftReference::kStart;
  o.inputs["t1_C"] = {3, 0.0625, 0.0};
  o.inputs["t2_C"] = {11, 0.0625, 0.0};
  o.control = {13, 400, 300};
  return o;
}

// A plan of the 30 um / 250 s curve over 1500 mm, standalone or handing K0, slope and reference
// over to the drift action.
CompensationPlan RequirementsPlan(bool combined) {
  PlanOptions p;
  p.direction = -1;
  p.sign = ExpectedSign(p.direction, p.control_dk);
  p.start_position_mm = -5600;
  p.machine_offset_mm = -812.5;
  p.sync_id_first = 100;
  p.sync_id_last = 149;
  p.save_r_first = 90;
  if (combined) {
    p.workpiece_k0_param = 99;
    p.workpiece_slope_param = 97;
    p.drift_alive_param = 100;
  }
  const fit::ArctanCurve curve = fit::ArctanCurve::FromFeatures({30.0, 250.0}, 4.0, 0.9);
  return BuildPlan(curve, 0.6, 1500.0, p);
}

TEST(ControlRequirements, PlanRequirementsAreTheThresholdsItsProgramStates) {
  for (bool combined : {false, true}) {
    SCOPED_TRACE(combined ? "combined" : "standalone");
    const CompensationPlan plan = RequirementsPlan(combined);
    const std::string nc = FormatNcProgram(plan, {"WHIRL_T", "WHIRL_T_RESET", "test"});
    const std::vector<ControlRequirement> r = PlanRequirements(plan, "WHIRL_T");
    ASSERT_NE(Find(r, "MD28250"), nullptr);
    EXPECT_EQ(Find(r, "MD28250")->value,
              HeaderThreshold(nc, "MD28250", R"(room for (\d+) synchronized)"));
    ASSERT_NE(Find(r, "MD32760"), nullptr);
    EXPECT_NEAR(Find(r, "MD32760")->value, HeaderThreshold(nc, "MD32760", R"(>= ([0-9.]+))"),
                0.5e-8);
    ASSERT_NE(Find(r, "MD32750"), nullptr);
    EXPECT_EQ(Find(r, "MD32750")->value, HeaderThreshold(nc, "MD32750", R"(= (\d+))"));
    EXPECT_EQ(Find(r, "MD32750")->axis, "Z");
    const double ac = HeaderThreshold(nc, "MD28254", R"(>= (\d+))");
    if (combined) {
      ASSERT_NE(Find(r, "MD28254"), nullptr);
      EXPECT_EQ(Find(r, "MD28254")->value, ac);
      EXPECT_EQ(Find(r, "MD28050"), nullptr);  // the slope handed over: no R parameter saved
    } else {
      EXPECT_TRUE(std::isnan(ac));  // the program uses no $AC_PARAM: no requirement
      EXPECT_EQ(Find(r, "MD28254"), nullptr);
      ASSERT_NE(Find(r, "MD28050"), nullptr);
      EXPECT_EQ(Find(r, "MD28050")->value, 94);  // R90..R93
    }
  }
}

TEST(ControlRequirements, DriftRequirementsAreTheThresholdsItsProgramStates) {
  const drift::DriftModel k = RequirementsModel("k0_um", 1.0), g = RequirementsModel("g_um", 2.0);
  const DriftActionOptions o = RequirementsDriftOptions();
  const std::string nc = FormatDriftNcProgram(k, o, "test", &g);
  const std::vector<ControlRequirement> r = DriftRequirements(k, o, &g);
  EXPECT_EQ(Find(r, "MD10300")->value,
            HeaderThreshold(nc, "MD10300", R"(MD10300 \$MN_FASTIO_ANA_NUM_INPUTS >= (\d+))"));
  EXPECT_EQ(Find(r, "MD10300")->value, 11);
  EXPECT_EQ(Find(r, "MD28254")->value,
            HeaderThreshold(nc, "MD28254", R"(MD28254 \$MC_MM_NUM_AC_PARAM >= (\d+))"));
  EXPECT_EQ(Find(r, "MD28250")->value,
            HeaderThreshold(nc, "MD28250", R"(room for (\d+) static actions)"));
  EXPECT_EQ(Find(r, "MD32750")->value, 3);  // bit 0 and bit 1: the slope mode
  EXPECT_DOUBLE_EQ(Find(r, "MD32760")->value, DriftSlopeBound(g, o));
  EXPECT_EQ(Find(r, "MD28254")->stated, 300);  // the profile's control section
  // Without a slope model: bit 0 only, no slope bound.
  DriftActionOptions offset_only = o;
  offset_only.workpiece_slope_param = -1;
  const std::vector<ControlRequirement> r0 = DriftRequirements(k, offset_only);
  EXPECT_EQ(Find(r0, "MD32750")->value, 1);
  EXPECT_EQ(Find(r0, "MD32760"), nullptr);
}

// The combined programs of one screw: the plan hands K0, slope and reference to the drift action.
// Read from the two headers, each program needs its own MD28254 and MD28250; together the box
// lists MD28254 once with the larger, MD28250 once with the sum.
TEST(ControlRequirements, TwoProgramsTogetherListEachDatumOnceWithWhatBothNeed) {
  const drift::DriftModel k = RequirementsModel("k0_um", 1.0), g = RequirementsModel("g_um", 2.0);
  const DriftActionOptions o = RequirementsDriftOptions();
  const CompensationPlan plan = RequirementsPlan(true);
  const std::string plan_nc = FormatNcProgram(plan, {"WHIRL_T", "WHIRL_T_RESET", "test"});
  const std::string drift_nc = FormatDriftNcProgram(k, o, "test", &g);
  const double ac_plan = HeaderThreshold(plan_nc, "MD28254", R"(>= (\d+))");
  const double ac_drift =
      HeaderThreshold(drift_nc, "MD28254", R"(MD28254 \$MC_MM_NUM_AC_PARAM >= (\d+))");
  ASSERT_NE(ac_plan, ac_drift);  // two different thresholds in the two headers
  const std::vector<ControlRequirement> drift = DriftRequirements(k, o, &g),
                                        planned = PlanRequirements(plan, "WHIRL_T");
  for (const auto& both : {MergeRequirements(drift, planned), MergeRequirements(planned, drift)}) {
    for (const char* datum : {"MD10300", "MD28050", "MD28250", "MD28254", "MD32750", "MD32760"})
      EXPECT_EQ(Count(both, datum), 1) << datum;
    EXPECT_EQ(Find(both, "MD28254")->value, std::max(ac_plan, ac_drift));
    EXPECT_EQ(Find(both, "MD28250")->value,
              HeaderThreshold(plan_nc, "MD28250", R"(room for (\d+) synchronized)") +
                  HeaderThreshold(drift_nc, "MD28250", R"(room for (\d+) static actions)"));
    EXPECT_EQ(Find(both, "MD32750")->value, 3);
    EXPECT_DOUBLE_EQ(Find(both, "MD32760")->value, plan.max_abs_slope + DriftSlopeBound(g, o));
    EXPECT_EQ(Find(both, "MD28254")->uses.size(), 2u);  // both programs named
    EXPECT_EQ(Find(both, "MD28254")->stated, 300);
  }
}

TEST(ControlRequirements, OneSentenceWithRuleUsesAndTheProfilesValue) {
  ControlRequirement ac =
      MakeRequirement("MD28254 $MC_MM_NUM_AC_PARAM", "", RequirementRule::kAtLeast,
                      RequirementMerge::kMax, 116, 0, "$AC_PARAM up to index 115 (A)");
  EXPECT_EQ(ToString(ac), "MD28254 $MC_MM_NUM_AC_PARAM >= 116: $AC_PARAM up to index 115 (A)");
  ac.stated = 300;
  EXPECT_EQ(ToString(ac),
            "MD28254 $MC_MM_NUM_AC_PARAM >= 116: $AC_PARAM up to index 115 (A) (profile: 300)");
  const ControlRequirement bits =
      MakeRequirement("MD32750 $MA_TEMP_COMP_TYPE", "Z", RequirementRule::kBits,
                      RequirementMerge::kUnion, 1, 0, "SD43900 (A)");
  EXPECT_EQ(ToString(bits), "MD32750 $MA_TEMP_COMP_TYPE on axis Z: bit 0 set: SD43900 (A)");
  ControlRequirement more = bits;
  more.value = 2;
  more.uses = {"SD43910 (B)"};
  const std::vector<ControlRequirement> m = MergeRequirements({bits}, {more});
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(ToString(m[0]),
            "MD32750 $MA_TEMP_COMP_TYPE on axis Z: bits 0 and 1 set (= 3): SD43900 (A); "
            "SD43910 (B)");
  // Another axis is another datum.
  ControlRequirement x = bits;
  x.axis = "X";
  EXPECT_EQ(MergeRequirements({bits}, {x}).size(), 2u);
}

}  // namespace
}  // namespace whirl::interp
