// The ISO 3408-3 tolerance table (shipped data file and loader errors) and the class verdict.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "lead/iso3408.h"
#include "core/error.h"
#include "support/scratch_dir.h"

namespace whirl::lead {
namespace {

const std::filesystem::path kTable =
    std::filesystem::path(WHIRL_SOURCE_DIR) / "datasets/standards/iso3408_3_lead_tolerances.csv";

TEST(IsoTable, ShippedFileHoldsTheReferenceCells) {
  const IsoToleranceTable t = ReadIsoToleranceTable(kTable);
  // Cells of the ISO 3408-3 table (datasets/standards/README.md; confirmed ones marked *).
  auto p3 = t.Lookup(IsoClass::kP3, 900);  // 800-1000: 21*/17
  ASSERT_TRUE(p3);
  EXPECT_EQ(p3->e_p_um, 21);
  EXPECT_EQ(*p3->v_up_um, 17);
  EXPECT_EQ(p3->v_300p_um, 12);
  EXPECT_EQ(*p3->v_2pi_p_um, 6);
  auto p5 = t.Lookup(IsoClass::kP5, 5100);  // 5000-6300: 170/119*
  ASSERT_TRUE(p5);
  EXPECT_EQ(p5->e_p_um, 170);
  EXPECT_EQ(*p5->v_up_um, 119);
  auto p1 = t.Lookup(IsoClass::kP1, 4500);  // 4000-5000: 39*/25
  ASSERT_TRUE(p1);
  EXPECT_EQ(p1->e_p_um, 39);
  EXPECT_EQ(*p1->v_up_um, 25);
  // Boundaries: 315 belongs to the first row, just above to the second.
  EXPECT_EQ(t.Lookup(IsoClass::kP1, 315)->e_p_um, 6);
  EXPECT_EQ(t.Lookup(IsoClass::kP1, 315.001)->e_p_um, 7);
  // P1 is not tabulated beyond 6300 mm; P3 is.
  EXPECT_FALSE(t.Lookup(IsoClass::kP1, 7000));
  EXPECT_TRUE(t.Lookup(IsoClass::kP3, 7000));
  // T classes: e_p derived from v_300p, no v_up, no v_2pi.
  auto t7 = t.Lookup(IsoClass::kT7, 3000);
  ASSERT_TRUE(t7);
  EXPECT_DOUBLE_EQ(t7->e_p_um, 3000.0 / 300.0 * 52.0);
  EXPECT_FALSE(t7->v_up_um);
  EXPECT_FALSE(t7->v_2pi_p_um);
  EXPECT_EQ(t.Lookup(IsoClass::kT10, 3000)->v_300p_um, 210);
  // Every e_p and v_up grows (weakly) with l_u and with the class number.
  for (IsoClass c : {IsoClass::kP1, IsoClass::kP3, IsoClass::kP5}) {
    double last_ep = 0, last_vu = 0;
    for (double lu = 100; lu <= 6300; lu += 50) {
      auto tol = t.Lookup(c, lu);
      ASSERT_TRUE(tol);
      EXPECT_GE(tol->e_p_um, last_ep);
      EXPECT_GE(*tol->v_up_um, last_vu);
      last_ep = tol->e_p_um;
      last_vu = *tol->v_up_um;
    }
  }
  for (double lu = 100; lu <= 6300; lu += 50) {
    EXPECT_LE(t.Lookup(IsoClass::kP1, lu)->e_p_um, t.Lookup(IsoClass::kP3, lu)->e_p_um);
    EXPECT_LE(t.Lookup(IsoClass::kP3, lu)->e_p_um, t.Lookup(IsoClass::kP5, lu)->e_p_um);
  }
  // The caveat is carried in the file's comments.
  bool caveat = false;
  for (const auto& c : t.comments) caveat = caveat || c.find("CAVEAT") != std::string::npos;
  EXPECT_TRUE(caveat);
}

LeadMetrics Metrics(double lu, double ea, double vu, double v300, std::optional<double> v2pi) {
  LeadMetrics m;
  m.useful_travel_mm = lu;
  m.e_a_um = ea;
  m.v_u_um = vu;
  m.v_300_um = v300;
  m.v_2pi_um = v2pi;
  return m;
}

TEST(IsoVerdict, PicksTheTightestClassWhoseEveryCheckHolds) {
  const IsoToleranceTable t = ReadIsoToleranceTable(kTable);
  // l_u 5100: P1 48/30 v300 6 v2pi 4; P3 94/58 12 6; P5 170/119 23 8.
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, 40, 20, 5, 3), t).reached, IsoClass::kP1);
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, -40, 20, 5, 3), t).reached, IsoClass::kP1);
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, 49, 20, 5, 3), t).reached, IsoClass::kP3);
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, 40, 20, 5, 5), t).reached, IsoClass::kP3);
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, 100, 20, 5, 3), t).reached, IsoClass::kP5);
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, 100, 120, 20, 3), t).reached, IsoClass::kT7);
  // T7: e_p = 5100/300*52 = 884.
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, 880, 500, 50, 30), t).reached, IsoClass::kT7);
  EXPECT_EQ(EvaluateIsoClass(Metrics(5100, 900, 500, 50, 30), t).reached, IsoClass::kT10);
  const IsoVerdict none = EvaluateIsoClass(Metrics(5100, 900, 500, 211, 30), t);
  EXPECT_EQ(none.reached, IsoClass::kNone);
  EXPECT_NE(none.message.find("v_300"), std::string::npos) << none.message;
  // Unknown v_2pi: left out of the P checks and said so.
  const IsoVerdict unknown = EvaluateIsoClass(Metrics(5100, 40, 20, 5, std::nullopt), t);
  EXPECT_EQ(unknown.reached, IsoClass::kP1);
  EXPECT_FALSE(unknown.v_2pi_evaluated);
  EXPECT_NE(unknown.message.find("v_2pi not evaluated"), std::string::npos);
  // Beyond P1's table: P1 cannot be reached however good the screw.
  EXPECT_EQ(EvaluateIsoClass(Metrics(7000, 0, 0, 0, 0), t).reached, IsoClass::kP3);
}

class BadTable : public ::testing::Test {
 protected:
  std::filesystem::path dir_ = whirl::test::ScratchDir() / "whirl_iso_table";
  void SetUp() override { std::filesystem::create_directories(dir_); }
  std::string Error(const std::string& body) {
    const auto p = dir_ / "t.csv";
    std::ofstream(p) << kHeader << body << kTail;
    try {
      ReadIsoToleranceTable(p);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  static constexpr const char* kHeader =
      "class,lu_min_mm,lu_max_mm,e_p_um,v_up_um,v_300p_um,v_2pi_p_um,confirmed_e_p,"
      "confirmed_v_up,confirmed_v_300p,confirmed_v_2pi_p\n";
  static constexpr const char* kTail =
      "3,0,1000,21,17,12,6,1,0,1,0\n5,0,1000,40,35,23,8,0,1,0,0\n"
      "7,0,100000,-1,-1,52,-1,0,0,0,0\n10,0,100000,-1,-1,210,-1,0,0,1,0\n";
};

TEST_F(BadTable, ErrorsNameLineColumnAndRule) {
  EXPECT_EQ(Error("1,0,1000,11,9,6,4,0,0,0,0\n"), "");
  std::string e = Error("2,0,1000,11,9,6,4,0,0,0,0\n");
  EXPECT_NE(e.find("t.csv:2"), std::string::npos) << e;
  EXPECT_NE(e.find("'class'"), std::string::npos) << e;
  e = Error("1,0,1000,11,-1,6,4,0,0,0,0\n");
  EXPECT_NE(e.find("'v_up_um'"), std::string::npos) << e;
  e = Error("1,0,1000,11,9,0,4,0,0,0,0\n");
  EXPECT_NE(e.find("'v_300p_um'"), std::string::npos) << e;
  e = Error("1,0,1000,11,9,6,4,2,0,0,0\n");
  EXPECT_NE(e.find("'confirmed_e_p'"), std::string::npos) << e;
  e = Error("1,0,500,8,7,6,4,0,0,0,0\n1,600,1000,11,9,6,4,0,0,0,0\n");
  EXPECT_NE(e.find("t.csv:3"), std::string::npos) << e;
  EXPECT_NE(e.find("contiguous"), std::string::npos) << e;
  e = Error("1,0,0,8,7,6,4,0,0,0,0\n");
  EXPECT_NE(e.find("'lu_max_mm'"), std::string::npos) << e;
  e = Error("");  // no P1 row
  EXPECT_NE(e.find("P1"), std::string::npos) << e;
  EXPECT_THROW(ReadIsoToleranceTable(dir_ / "missing.csv"), InputError);
}

}  // namespace
}  // namespace whirl::lead
