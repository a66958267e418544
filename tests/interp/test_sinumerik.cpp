// 840D setting data: the invariant (compensation reconstructed from SD43900/43910/43920 follows the
// curve within the tolerance), the SD definitions, the slope cap, writers and the NC golden file.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <random>
#include <regex>
#include <sstream>
#include <vector>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "fit/arctan_curve.h"
#include "interp/sinumerik.h"

namespace whirl::interp {
namespace {

struct Case {
  fit::ArctanCurve curve;
  double feed_mm_s;
  double thread_mm;
  PlanOptions options;
};

Case RandomCase(std::mt19937& rng) {
  std::uniform_real_distribution<double> ul(5.0, 120.0), uts(80.0, 600.0), uk(0.5, 10.0),
      ufeed(0.3, 1.5), uthread(800.0, 6000.0), upos(-3000.0, 3000.0), utol(0.1, 2.0);
  Case c;
  c.curve = fit::ArctanCurve{ul(rng), uts(rng), uk(rng)};
  c.feed_mm_s = ufeed(rng);
  c.thread_mm = uthread(rng);
  c.options.tolerance_um = utol(rng);
  c.options.start_position_mm = upos(rng);
  c.options.machine_offset_mm = upos(rng);
  c.options.direction = rng() % 2 == 0 ? 1 : -1;
  c.options.sign = rng() % 2 == 0 ? SignConvention::kAdd : SignConvention::kSubtract;
  // The machine fact that makes this sign consistent with the direction (ExpectedSign).
  c.options.control_dk = ExpectedSign(c.options.direction, ControlDk::kAdded) == c.options.sign
                             ? ControlDk::kAdded
                             : ControlDk::kSubtracted;
  c.options.check_step_s = 0.5;
  c.options.md32760 = kMd32760Max;  // random feeds and curves reach slopes up to ~0.04
  c.options.sync_id_first = 1;      // the whole range: enough for the tightest random tolerance
  c.options.sync_id_last = 255;
  c.options.save_r_first = 90;
  return c;
}

TEST(Sinumerik, ReconstructedCompensationFollowsTheCurveWithinTolerance) {
  std::mt19937 rng(31);
  int seen[2][2] = {{0, 0}, {0, 0}};
  for (int trial = 0; trial < 120; ++trial) {
    const Case c = RandomCase(rng);
    const CompensationPlan plan = BuildPlan(c.curve, c.feed_mm_s, c.thread_mm, c.options);
    ++seen[c.options.direction > 0][c.options.sign == SignConvention::kAdd];
    const double t_end = c.thread_mm / c.feed_mm_s;
    const int dense = 30000;
    double worst = 0;
    for (int i = 0; i <= dense; ++i) {
      const double t = t_end * (i + 0.5) / (dense + 1);
      const double p = AxisPositionMm(c.options, c.feed_mm_s, t);
      worst = std::max(worst, std::abs(AppliedCompensationUm(plan, p) - c.curve.ElongationUm(t)));
    }
    EXPECT_LE(worst, c.options.tolerance_um) << "trial " << trial << " dir " << c.options.direction
                                             << " sign " << ToString(c.options.sign);
    // Beyond the thread end the plateau is held.
    const double p_after = AxisPositionMm(c.options, c.feed_mm_s, t_end * 1.1);
    EXPECT_NEAR(AppliedCompensationUm(plan, p_after), c.curve.max_elongation_um, 0.5e-3 + 1e-9)
        << "within the printed resolution of SD43900 (1 nm)";
  }
  for (auto& row : seen)
    for (int n : row) EXPECT_GT(n, 10) << "every direction/sign combination is exercised";
}

TEST(Sinumerik, SettingDataFollowTheDocumentedFormulas) {
  std::mt19937 rng(32);
  for (int trial = 0; trial < 40; ++trial) {
    const Case c = RandomCase(rng);
    const CompensationPlan plan = BuildPlan(c.curve, c.feed_mm_s, c.thread_mm, c.options);
    const double s = c.options.sign == SignConvention::kAdd ? 1.0 : -1.0;
    ASSERT_GE(plan.segments.size(), 2u);
    EXPECT_EQ(plan.point_count, plan.segments.size() + 1);
    EXPECT_GE(plan.uniform_point_count, plan.point_count);
    // Every written value is the formula rounded to its printed resolution (kDecimals*).
    const double p0 = c.options.machine_offset_mm + c.options.start_position_mm;
    const double half_pos = 0.5e-4 + 1e-9;
    EXPECT_NEAR(plan.segments.front().p_a_mm, p0, half_pos);
    EXPECT_NEAR(plan.segments.back().p_b_mm, p0 + c.options.direction * c.thread_mm,
                1e-6 + half_pos);
    for (std::size_t i = 0; i < plan.segments.size(); ++i) {
      const CompensationSegment& g = plan.segments[i];
      const double p_a = p0 + c.options.direction * c.feed_mm_s * g.t_a_s;
      const double p_b = p0 + c.options.direction * c.feed_mm_s * g.t_b_s;
      EXPECT_NEAR(g.p_a_mm, p_a, half_pos);
      EXPECT_EQ(g.p_a_mm, RoundTo(g.p_a_mm, kDecimalsPositionMm));
      EXPECT_DOUBLE_EQ(g.l_a_um, c.curve.ElongationUm(g.t_a_s));
      EXPECT_NEAR(g.sd43900_mm, s * g.l_a_um / 1000.0, 0.5e-6 + 1e-15);
      EXPECT_EQ(g.sd43900_mm, RoundTo(g.sd43900_mm, kDecimalsSd43900Mm));
      EXPECT_EQ(g.sd43920_mm, g.p_a_mm);
      EXPECT_NEAR(g.sd43910, s * (g.l_b_um - g.l_a_um) / 1000.0 / (p_b - p_a), 0.5e-8 + 1e-13);
      EXPECT_EQ(g.sd43910, RoundTo(g.sd43910, kDecimalsSd43910));
      EXPECT_LE(std::abs(g.sd43910), c.options.md32760);
      if (i > 0) {
        EXPECT_EQ(g.t_a_s, plan.segments[i - 1].t_b_s);
      }
    }
    EXPECT_EQ(plan.segments.back().sd43910, 0.0) << "the plateau segment is flat";
  }
}

TEST(Sinumerik, SlopeBeyondMd32760IsAnErrorNamingSegmentSlopeAndCap) {
  // 100 um in 10 s at 0.05 mm/s feed: slope ~0.2 mm/mm at the start, far above 0.01.
  const fit::ArctanCurve steep{100.0, 10.0, 3.0};
  PlanOptions o;
  try {
    BuildPlan(steep, 0.05, 100.0, o);
    FAIL() << "steep slope accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("segment 1"), std::string::npos) << m;
    EXPECT_NE(m.find("SD43910"), std::string::npos) << m;
    EXPECT_NE(m.find("0.01"), std::string::npos) << m;
  }
  // The same curve with a generous cap and a fast feed passes, and every slope respects the cap.
  o.md32760 = 0.1;
  const CompensationPlan plan = BuildPlan(steep, 2.0, 100.0, o);
  EXPECT_LE(plan.max_abs_slope, 0.1);
}

TEST(Sinumerik, BadOptionsThrow) {
  const fit::ArctanCurve c{30.0, 200.0, 3.0};
  PlanOptions o;
  o.tolerance_um = -0.5;
  EXPECT_THROW(BuildPlan(c, 0.5, 1000, o), InputError);
  o = PlanOptions{};
  o.direction = 0;
  EXPECT_THROW(BuildPlan(c, 0.5, 1000, o), InputError);
  o = PlanOptions{};
  o.md32760 = 0.2;
  EXPECT_THROW(BuildPlan(c, 0.5, 1000, o), InputError);
  o = PlanOptions{};
  o.axis = "Z;M30";
  EXPECT_THROW(BuildPlan(c, 0.5, 1000, o), InputError);
  EXPECT_THROW(BuildPlan(c, -0.5, 1000, PlanOptions{}), InputError);
  EXPECT_THROW(BuildPlan(c, 0.5, 0, PlanOptions{}), InputError);
  EXPECT_THROW(ParseSignConvention("plus"), InputError);
}

TEST(Sinumerik, JsonRoundTripReproducesThePlan) {
  std::mt19937 rng(33);
  const Case c = RandomCase(rng);
  const CompensationPlan plan = BuildPlan(c.curve, c.feed_mm_s, c.thread_mm, c.options);
  const nlohmann::json j = plan;
  const CompensationPlan back = nlohmann::json::parse(j.dump()).get<CompensationPlan>();
  ASSERT_EQ(back.segments.size(), plan.segments.size());
  for (double p = -4000; p <= 4000; p += 7.3)
    EXPECT_EQ(AppliedCompensationUm(back, p), AppliedCompensationUm(plan, p));
  EXPECT_EQ(back.options.sign, plan.options.sign);
  EXPECT_EQ(back.uniform_point_count, plan.uniform_point_count);
  nlohmann::json bad = j;
  bad["settings"]["tolerance"] = 1;  // typo'd key
  EXPECT_THROW(bad.get<CompensationPlan>(), InputError);
}

std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  std::istringstream in(line);
  while (std::getline(in, cell, ',')) cells.push_back(cell);
  if (!line.empty() && line.back() == ',') cells.push_back("");
  return cells;
}

TEST(Sinumerik, PlcCsvCarriesTheSettingDataExactlyWithFixedDecimals) {
  std::mt19937 rng(34);
  const Case c = RandomCase(rng);
  const CompensationPlan plan = BuildPlan(c.curve, c.feed_mm_s, c.thread_mm, c.options);
  const std::string csv = FormatPlcCsv(plan, {" made by the test"});
  std::istringstream in(csv);
  std::string line;
  std::vector<std::vector<std::string>> rows;
  std::getline(in, line);
  EXPECT_EQ(line, "# made by the test");
  while (std::getline(in, line))
    if (line[0] != '#') rows.push_back(SplitCells(line));
  ASSERT_EQ(rows.size(), plan.segments.size() + 2);  // header, segments, restore
  EXPECT_EQ(rows[0][8], "sd43900_mm");
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const auto& r = rows[i + 1];
    const CompensationSegment& g = plan.segments[i];
    for (const std::string& cell : r)
      EXPECT_EQ(cell.find_first_of("eE"), std::string::npos) << cell;
    EXPECT_EQ(r[1], FormatFixed(g.p_a_mm, kDecimalsPositionMm));
    EXPECT_EQ(std::stod(r[8]), g.sd43900_mm);  // the plan holds exactly the printed values
    EXPECT_EQ(r[8], FormatFixed(g.sd43900_mm, kDecimalsSd43900Mm));
    EXPECT_EQ(std::stod(r[9]), g.sd43910);
    EXPECT_EQ(r[9], FormatFixed(g.sd43910, kDecimalsSd43910));
    EXPECT_EQ(std::stod(r[10]), g.sd43920_mm);
  }
  const auto& last = rows.back();
  ASSERT_EQ(last.size(), 11u);
  EXPECT_EQ(last[0], "restore");
  EXPECT_EQ(last[1], FormatFixed(plan.segments.back().p_b_mm, kDecimalsPositionMm));
  for (int k = 8; k <= 10; ++k)
    EXPECT_EQ(last[k], "saved") << "no SD value 0 that reads as 'set 0'";
}

TEST(Sinumerik, PointsCsvEndsWithTheRestoreNotWithZeros) {
  std::mt19937 rng(36);
  const Case c = RandomCase(rng);
  const CompensationPlan plan = BuildPlan(c.curve, c.feed_mm_s, c.thread_mm, c.options);
  std::istringstream in(FormatPointsCsv(plan, {" report points"}));
  std::string line;
  std::vector<std::vector<std::string>> rows;
  while (std::getline(in, line))
    if (line[0] != '#') rows.push_back(SplitCells(line));
  ASSERT_EQ(rows.size(), plan.segments.size() + 2);  // header, one per breakpoint
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    EXPECT_EQ(std::stod(rows[i + 1][3]), plan.segments[i].sd43900_mm);
    EXPECT_EQ(rows[i + 1][4], FormatFixed(plan.segments[i].sd43910, kDecimalsSd43910));
    for (const std::string& cell : rows[i + 1])
      EXPECT_EQ(cell.find_first_of("eE"), std::string::npos);
  }
  const auto& last = rows.back();
  EXPECT_EQ(std::stod(last[0]), RoundTo(plan.segments.back().t_b_s, kDecimalsTimeS));
  for (int k = 3; k <= 5; ++k) EXPECT_EQ(last[k], "saved");
}

TEST(Sinumerik, FormatFixedHasNoExponentAndNoNegativeZero) {
  EXPECT_EQ(FormatFixed(-4.8228920410787164e-05, kDecimalsSd43910), "-0.00004823");
  EXPECT_EQ(FormatFixed(0.00029224836244359006, kDecimalsSd43900Mm), "0.000292");
  EXPECT_EQ(FormatFixed(-1e-12, 4), "0.0000");
  EXPECT_EQ(FormatFixed(1e300, 4).find('e'), std::string::npos);
  EXPECT_EQ(RoundTo(-0.00004823, 8), -0.00004823);
}

TEST(Sinumerik, InconsistentSignIsRefusedWithTheRule) {
  PlanOptions o;
  o.direction = -1;  // control adds dK (default): the consistent sign is 'add'
  o.sign = SignConvention::kSubtract;
  try {
    o.Validate();
    FAIL() << "inconsistent sign accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'add' here"), std::string::npos) << e.what();
  }
  o.sign = ExpectedSign(o.direction, o.control_dk);
  EXPECT_EQ(o.sign, SignConvention::kAdd);
  EXPECT_NO_THROW(o.Validate());
  EXPECT_EQ(ExpectedSign(1, ControlDk::kAdded), SignConvention::kSubtract);
  EXPECT_EQ(ExpectedSign(1, ControlDk::kSubtracted), SignConvention::kAdd);
  EXPECT_EQ(ExpectedSign(-1, ControlDk::kSubtracted), SignConvention::kSubtract);
}

// A fixed small plan (hand-made values) for the format of the NC program.
CompensationPlan SmallPlan() {
  CompensationPlan plan;
  plan.options.axis = "Z";
  plan.options.start_position_mm = 100.0;
  plan.options.machine_offset_mm = -500.0;
  plan.options.direction = 1;
  plan.options.sign = SignConvention::kSubtract;
  plan.options.sync_id_first = 200;
  plan.options.sync_id_last = 204;
  plan.options.save_r_first = 90;
  plan.axial_feed_mm_s = 0.5;
  plan.thread_length_mm = 100.0;
  plan.cutting_time_s = 200.0;
  const double t[] = {0.0, 20.0, 60.0, 200.0};
  const double l[] = {0.0, 12.5, 25.0, 30.0};
  for (int i = 0; i < 3; ++i) {
    CompensationSegment s;
    s.t_a_s = t[i];
    s.t_b_s = t[i + 1];
    s.p_a_mm = -400.0 + 0.5 * t[i];
    s.p_b_mm = -400.0 + 0.5 * t[i + 1];
    s.l_a_um = l[i];
    s.l_b_um = l[i + 1];
    s.sd43900_mm = -l[i] / 1000.0;
    s.sd43910 = -(l[i + 1] - l[i]) / 1000.0 / (s.p_b_mm - s.p_a_mm);
    s.sd43920_mm = s.p_a_mm;
    plan.segments.push_back(s);
    plan.max_abs_slope = std::max(plan.max_abs_slope, std::abs(s.sd43910));
  }
  plan.point_count = 4;
  plan.max_deviation_um = 0.4321;
  return plan;
}

TEST(Sinumerik, NcProgramMatchesGoldenFile) {
  NcProgramInfo info;
  info.curve_source = "golden test plan";
  const std::string nc = FormatNcProgram(SmallPlan(), info);
  const std::string golden_path =
      std::string(WHIRL_SOURCE_DIR) + "/tests/interp/golden/small_plan.spf";
  if (std::getenv("WHIRL_UPDATE_GOLDEN") != nullptr) WriteFileAtomic(golden_path, nc);
  EXPECT_EQ(nc, ReadTextFile(golden_path)) << "regenerate with WHIRL_UPDATE_GOLDEN=1 after a "
                                              "deliberate format change; actual:\n"
                                           << nc;
  const std::string reset = FormatNcResetProgram(SmallPlan().options, info);
  const std::string reset_path =
      std::string(WHIRL_SOURCE_DIR) + "/tests/interp/golden/small_plan_reset.spf";
  if (std::getenv("WHIRL_UPDATE_GOLDEN") != nullptr) WriteFileAtomic(reset_path, reset);
  EXPECT_EQ(reset, ReadTextFile(reset_path)) << "actual:\n" << reset;
}

// The plan that hands K0, slope and reference to the drift action (interp/drift_action.h).
TEST(Sinumerik, HandedOverNcProgramMatchesGoldenFile) {
  CompensationPlan plan = SmallPlan();
  plan.options.workpiece_k0_param = 99;
  plan.options.drift_alive_param = 100;
  plan.options.workpiece_slope_param = 97;
  NcProgramInfo info;
  info.curve_source = "golden test plan";
  const std::string nc = FormatNcProgram(plan, info) + FormatNcResetProgram(plan.options, info);
  const std::string path =
      std::string(WHIRL_SOURCE_DIR) + "/tests/interp/golden/small_plan_handover.spf";
  if (std::getenv("WHIRL_UPDATE_GOLDEN") != nullptr) WriteFileAtomic(path, nc);
  EXPECT_EQ(nc, ReadTextFile(path)) << "actual:\n" << nc;
  EXPECT_EQ(nc.find("SA_TEMP_COMP_SLOPE"), std::string::npos) << "the plan must not write SD43910";
  EXPECT_EQ(nc.find("SA_TEMP_COMP_ABS_VALUE"), std::string::npos);
}

TEST(Sinumerik, NcProgramValuesReconstructTheCompensation) {
  // Parse the synchronized actions back: the printed values reproduce the plan within the printed
  // precision, in both directions of travel.
  std::mt19937 rng(35);
  for (int trial = 0; trial < 10; ++trial) {
    const Case c = RandomCase(rng);
    const CompensationPlan plan = BuildPlan(c.curve, c.feed_mm_s, c.thread_mm, c.options);
    const std::string nc = FormatNcProgram(plan);
    const std::regex action(
        R"(ID=(\d+) WHEN \$AA_IM\[Z\](>=|<=)(-?[0-9.]+) DO \$\$SA_TEMP_COMP_ABS_VALUE\[Z\]=(-?[0-9.]+) \$\$SA_TEMP_COMP_SLOPE\[Z\]=(-?[0-9.]+) \$\$SA_TEMP_COMP_REF_POSITION\[Z\]=(-?[0-9.]+))");
    std::size_t count = 0;
    for (auto it = std::sregex_iterator(nc.begin(), nc.end(), action); it != std::sregex_iterator();
         ++it) {
      const auto& m = *it;
      const std::size_t id = std::stoul(m[1]) - c.options.sync_id_first;  // the first included
      ASSERT_LT(id, plan.segments.size());
      const CompensationSegment& s = plan.segments[id];
      EXPECT_EQ(m[2].str(), c.options.direction > 0 ? ">=" : "<=");
      EXPECT_NEAR(std::stod(m[3]), s.p_a_mm, 0.5e-4);
      EXPECT_NEAR(std::stod(m[4]), s.sd43900_mm, 0.5e-6);
      EXPECT_NEAR(std::stod(m[5]), s.sd43910, 0.5e-8);
      EXPECT_NEAR(std::stod(m[6]), s.sd43920_mm, 0.5e-4);
      ++count;
    }
    EXPECT_EQ(count, plan.segments.size()) << "every segment, the first too, is an action";
    EXPECT_NE(nc.find("MD32750 $MA_TEMP_COMP_TYPE = 3"), std::string::npos);
    // Nothing of the plan is written by the part program itself: its only writes of the setting
    // data give back values an earlier, aborted run saved in R parameters.
    const std::regex part_program_write(R"(\n\$SA_TEMP_COMP_\w+\[Z\]=([^\n]*))");
    for (auto it = std::sregex_iterator(nc.begin(), nc.end(), part_program_write);
         it != std::sregex_iterator(); ++it)
      EXPECT_TRUE(std::regex_match((*it)[1].str(), std::regex(R"(R\d+)"))) << (*it)[0];
  }
}

// The program cancels every ID of its range: without a range stated by the machine builder (a
// profile or explicit flags) there is no program, never a default 1..255.
// Both programs of `plan` are refused with a message holding every one of `words`.
void ExpectBothProgramsRefused(const CompensationPlan& plan, const std::vector<std::string>& words) {
  using Make = std::function<std::string()>;
  for (const Make& make : {Make([&] { return FormatNcProgram(plan); }),
                           Make([&] { return FormatNcResetProgram(plan.options); })}) {
    try {
      make();
      ADD_FAILURE() << "NC program written; expected a refusal naming " << words.front();
    } catch (const InputError& e) {
      for (const std::string& w : words)
        EXPECT_NE(std::string(e.what()).find(w), std::string::npos) << e.what();
    }
  }
}

TEST(Sinumerik, NcProgramsNeedTheReservedIdRange) {
  CompensationPlan plan = SmallPlan();
  plan.options.sync_id_first = plan.options.sync_id_last = 0;
  EXPECT_NO_THROW(plan.options.Validate()) << "a plan without IDs can be built and checked";
  ExpectBothProgramsRefused(plan, {"no synchronized-action IDs"});
  EXPECT_EQ(PlanOptions{}.sync_id_first, 0) << "no default range";
  EXPECT_EQ(PlanOptions{}.sync_id_last, 0);
}

// The program saves what it finds in R<n>..R<n+3>, the user's R parameters: without a number
// stated by the machine builder (a profile or an explicit flag) there is no program, never a
// default R90..R93. A plan that hands its slope to the drift action saves nothing and needs none.
TEST(Sinumerik, NcProgramsNeedTheReservedRParameters) {
  EXPECT_EQ(PlanOptions{}.save_r_first, -1) << "no default R parameters";
  CompensationPlan plan = SmallPlan();
  plan.options.save_r_first = -1;
  EXPECT_NO_THROW(plan.options.Validate()) << "a plan without R parameters can be built";
  ExpectBothProgramsRefused(plan, {"no R parameters", "--save-r-first"});
  plan.options.workpiece_k0_param = 99;  // K0 handed over, the slope kept: still saves it
  plan.options.drift_alive_param = 100;
  EXPECT_THROW(FormatNcProgram(plan), InputError);
  plan.options.workpiece_slope_param = 97;  // everything handed over: no R parameter used
  const std::string nc = FormatNcProgram(plan) + FormatNcResetProgram(plan.options);
  EXPECT_EQ(std::regex_search(nc, std::regex(R"((^|[^A-Z_])\$?R\d)")), false) << nc;
  plan.options.save_r_first = 9997;
  EXPECT_THROW(plan.options.Validate(), InputError);
}

TEST(Sinumerik, ProgramNamesAreTheFileStemsAndSinumerikNames) {
  EXPECT_EQ(ProgramNameOf("out/WHIRL_COMP_2.SPF", "--nc"), "WHIRL_COMP_2");
  EXPECT_EQ(ProgramNameOf("ab.spf", "--nc"), "ab");
  EXPECT_EQ(ProgramNameOf(std::string(24, 'W') + ".SPF", "--nc"), std::string(24, 'W'));
  for (const std::string bad : {"1 my comp.spf", "my comp.spf", "A.SPF", "A1B.SPF", "AB-C.SPF",
                                "_AB.SPF", "AB$C.SPF", ".SPF", "AB\nM30.SPF"}) {
    try {
      ProgramNameOf("dir/" + bad, "--nc");
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--nc"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("24"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(ProgramNameOf(std::string(25, 'W') + ".SPF", "--nc"), InputError);
  EXPECT_THROW(CheckDistinctProgramNames("WHIRL_A", "whirl_a"), InputError);
  EXPECT_NO_THROW(CheckDistinctProgramNames("WHIRL_A", "WHIRL_A_RESET"));
  // The headers name the programs they are given; a name the control refuses is an error.
  NcProgramInfo info;
  info.program_name = "THREAD_COMP";
  info.reset_program_name = "THREAD_UNDO";
  const std::string nc = FormatNcProgram(SmallPlan(), info);
  EXPECT_EQ(nc.rfind("; THREAD_COMP: ", 0), 0u) << nc.substr(0, 80);
  EXPECT_NE(nc.find("call THREAD_UNDO after"), std::string::npos);
  EXPECT_EQ(nc.find("WHIRL_TEMP_COMP"), std::string::npos) << "no other program named";
  const std::string reset = FormatNcResetProgram(SmallPlan().options, info);
  EXPECT_EQ(reset.rfind("; THREAD_UNDO: ", 0), 0u);
  EXPECT_NE(reset.find("aborted THREAD_COMP run"), std::string::npos);
  info.reset_program_name = "thread_comp";
  EXPECT_THROW(FormatNcProgram(SmallPlan(), info), InputError);
  info.reset_program_name = "1 my comp";
  EXPECT_THROW(FormatNcResetProgram(SmallPlan().options, info), InputError);
}

TEST(Sinumerik, PositionsAndAlarmsHavePhysicalAndUserRanges) {
  for (double v : {1e308, -1e6, 1.0001e5, double(NAN), double(INFINITY)}) {
    PlanOptions o;
    o.machine_offset_mm = v;
    EXPECT_THROW(o.Validate(), InputError) << "machine_offset_mm " << v;
    o = PlanOptions{};
    o.start_position_mm = v;
    EXPECT_THROW(o.Validate(), InputError) << "start_position_mm " << v;
  }
  PlanOptions o;
  o.machine_offset_mm = -99999.0;
  EXPECT_NO_THROW(o.Validate());
  // SETAL numbers: the user cycle alarms only (60000..64999 belong to Siemens' cycles).
  for (int alarm : {60000, 64999, 70000}) {
    o = PlanOptions{};
    o.start_alarm = alarm;
    EXPECT_THROW(o.Validate(), InputError) << alarm;
    o = PlanOptions{};
    o.drift_missing_alarm = alarm;
    EXPECT_THROW(o.Validate(), InputError) << alarm;
  }
  o = PlanOptions{};
  o.drift_alive_param = 100;
  o.drift_missing_alarm = 65010;
  o.start_alarm = 65012;  // the drift check's third number
  EXPECT_THROW(o.Validate(), InputError);
  o.start_alarm = 65013;
  EXPECT_NO_THROW(o.Validate());
}

}  // namespace
}  // namespace whirl::interp
