#include <gtest/gtest.h>

#include <filesystem>

#include "core/atomic_file.h"
#include "core/curve.h"
#include "core/error.h"
#include "core/process.h"
#include "support/scratch_dir.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

fs::path FilesScratch(const std::string& name) {
  const fs::path d = whirl::test::ScratchDir() / ("whirl_test_core_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

TEST(AtomicFile, FailedWriteLeavesOldFileAndNoTemporary) {
  const fs::path d = FilesScratch("atomic");
  WriteFileAtomic(d / "a.txt", "old");
  EXPECT_THROW(WriteFileAtomic(d / "missing_dir" / "a.txt", "x"), InputError);
  EXPECT_EQ(ReadTextFile(d / "a.txt"), "old");
  WriteFileAtomic(d / "a.txt", "new");
  EXPECT_EQ(ReadTextFile(d / "a.txt"), "new");
  int files = 0;
  for (const auto& e : fs::directory_iterator(d)) (void)e, ++files;
  EXPECT_EQ(files, 1);
}

TEST(ProcessTable, RoundTripAndMissingColumn) {
  const fs::path d = FilesScratch("table");
  ProcessTable t;
  t.inputs = {{60, 80, 10, 3.5, 180}, {65, 50, 6, 3, 150}};
  t.targets = {{30.5, 210}, {12.25, 180}};
  t.comments = {"test table"};
  WriteProcessTable(d / "t.csv", t);
  const ProcessTable r = ReadProcessTable(d / "t.csv", true);
  ASSERT_EQ(r.inputs.size(), 2u);
  EXPECT_EQ(r.inputs[1].raceway_radius_mm, 3.0);
  EXPECT_EQ(r.targets[0].settle_time_s, 210.0);
  WriteFileAtomic(d / "bad.csv", "hardness_hrc,diameter_mm,pitch_mm,cutting_speed_m_min\n1,2,3,4\n");
  try {
    ReadProcessTable(d / "bad.csv", false);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("missing column 'raceway_radius_mm'"), std::string::npos);
  }
}

TEST(Curve, RejectsNonIncreasingTimeAndGaps) {
  const fs::path d = FilesScratch("curve");
  WriteFileAtomic(d / "ok.csv", "time_s,elongation_um\n0,0\n1,1\n2,1.5\n3,1.7\n");
  EXPECT_EQ(ReadElongationCurve(d / "ok.csv").size(), 4u);
  WriteFileAtomic(d / "back.csv", "time_s,elongation_um\n0,0\n1,1\n1,1.5\n");
  EXPECT_THROW(ReadElongationCurve(d / "back.csv"), InputError);
  WriteFileAtomic(d / "gap.csv", "time_s,elongation_um\n0,0\n1,1\n2,1\n3,1\n40,2\n");
  EXPECT_THROW(ReadElongationCurve(d / "gap.csv"), InputError);
}

}  // namespace
}  // namespace whirl
