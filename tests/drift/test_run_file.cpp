// Run files: columns by suffix, time in s or min or missing, and clear errors for bad files.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "drift/run_file.h"
#include "support/scratch_dir.h"

namespace whirl::drift {
namespace {

std::string ErrorOf(const std::string& text) {
  try {
    ParseRun(text, "r.csv", RunState::kIdle);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(RunFile, ColumnsBySuffixAndTimeInMinutes) {
  const drift::Run r = ParseRun(
      "# test\ntime_s,a_C,b_C,x_um,spindle_rpm\n0,20,21,0,0\n60,21,22,1.5,1000\n"
      "120,22,22.5,2,1000\n",
      "dir/r.csv", RunState::kCutting);
  EXPECT_EQ(r.name, "r");
  EXPECT_EQ(r.state, RunState::kCutting);
  EXPECT_EQ(r.sensor_names, (std::vector<std::string>{"a_C", "b_C"}));
  EXPECT_EQ(r.error_names, (std::vector<std::string>{"x_um"}));
  EXPECT_EQ(r.other_names, (std::vector<std::string>{"spindle_rpm"}));
  EXPECT_EQ(r.time_min, (std::vector<double>{0, 1, 2}));
  EXPECT_FALSE(r.time_from_index);
  EXPECT_EQ(r.Rises()(2, 1), 1.5);
  EXPECT_EQ(r.line_numbers[0], 3);
}

TEST(RunFile, MissingTimeUsesTheSampleIndex) {
  const drift::Run r =
      ParseRun("time_min,a_C,e_um\n0,20,0\nnan,21,1\n,22,2\n", "r.csv", RunState::kIdle);
  EXPECT_TRUE(r.time_from_index);
  EXPECT_EQ(r.time_min, (std::vector<double>{0, 1, 2}));
  const drift::Run none = ParseRun("a_C,e_um\n20,0\n21,1\n", "r.csv", RunState::kIdle);
  EXPECT_TRUE(none.time_from_index);
}

TEST(RunFile, BadFilesGetClearErrors) {
  EXPECT_NE(ErrorOf("time_s,e_um\n0,1\n").find("no temperature column"), std::string::npos);
  const std::string cell = ErrorOf("time_s,a_C,e_um\n0,20,1\n1,abc,2\n");
  EXPECT_NE(cell.find("r.csv:3"), std::string::npos) << cell;
  EXPECT_NE(cell.find("a_C"), std::string::npos) << cell;
  const std::string nan_temp = ErrorOf("time_s,a_C,e_um\n0,nan,1\n");
  EXPECT_NE(nan_temp.find("r.csv:2"), std::string::npos) << nan_temp;
  const std::string order = ErrorOf("time_s,a_C\n0,20\n5,21\n5,22\n");
  EXPECT_NE(order.find("r.csv:4"), std::string::npos) << order;
  EXPECT_NE(order.find("increase"), std::string::npos) << order;
  EXPECT_NE(ErrorOf("time_s,time_min,a_C\n0,0,1\n").find("two time columns"), std::string::npos);
  const std::string hot = ErrorOf("time_s,a_C\n0,20\n1,2000\n");
  EXPECT_NE(hot.find("r.csv:3: column 'a_C': value 2000"), std::string::npos) << hot;
  EXPECT_NE(ErrorOf("time_s,a_C,b_C\n0,20\n").find("r.csv:2"), std::string::npos);
  EXPECT_NE(ErrorOf("time_s,a_C\n").find("r.csv"), std::string::npos);
  const drift::Run r = ParseRun("time_s,a_C\n0,20\n", "r.csv", RunState::kIdle);
  try {
    r.ErrorIndex("ch9_um");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ch9_um"), std::string::npos);
  }
}

TEST(RunFile, SplitAtStartsAndFormatRoundTrip) {
  std::string text = "time_s,a_C,e_um,spindle_rpm\n";
  const double rpm[] = {0, 0, 500, 500, 0, 0, 800, 800, 0};
  for (int k = 0; k < 9; ++k)
    text += std::to_string(k * 60) + "," + std::to_string(20 + k) + "," + std::to_string(k) + "," +
            std::to_string(rpm[k]) + "\n";
  const drift::Run log = ParseRun(text, "log.csv", RunState::kIdle);
  const auto runs = SplitAtStarts(log, "spindle_rpm");
  ASSERT_EQ(runs.size(), 2u);  // the idle rows before the first start belong to run 1
  EXPECT_EQ(runs[0].samples(), 6);
  EXPECT_EQ(runs[1].samples(), 3);
  EXPECT_EQ(runs[1].Rises()(0, 0), 0.0);
  EXPECT_EQ(runs[1].name, "log_2");
  const drift::Run back = ParseRun(FormatRun(runs[1], {"provenance"}), "b.csv", RunState::kIdle);
  EXPECT_EQ(back.temperature_C, runs[1].temperature_C);
  EXPECT_EQ(back.error_um, runs[1].error_um);
  EXPECT_EQ(back.time_min, runs[1].time_min);
  EXPECT_EQ(ErrorsFromStart(back).error_um(0, 0), 0.0);
}

}  // namespace
}  // namespace whirl::drift

namespace whirl::drift {
namespace {

TEST(RunFile, WriteRunsIsAllOrNothing) {
  const auto dir = whirl::test::ScratchDir() / "whirl_test_write_runs";
  std::filesystem::remove_all(dir);
  const drift::Run log =
      ParseRun("time_s,a_C,e_um\n0,20,0\n60,21,1\n120,22,2\n", "log.csv", RunState::kIdle);
  std::vector<drift::Run> runs{log.Slice(0, 2, "a"), log.Slice(2, 3, "b")};
  const auto first = WriteRuns(dir, runs, {"first"});
  const std::string a_before = ReadTextFile(dir / "a.csv");
  // The second file cannot be written (a directory sits at its name): the first stays as it was,
  // the message names the target and what it is, no temporary remains.
  std::filesystem::remove(dir / "b.csv");
  std::filesystem::create_directories(dir / "b.csv");
  try {
    WriteRuns(dir, runs, {"second"});
    ADD_FAILURE() << "a directory at b.csv was not refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'b.csv'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ReadTextFile(dir / "a.csv"), a_before);
  for (const auto& e : std::filesystem::directory_iterator(dir))
    EXPECT_FALSE(IsWhirlTemporary(e.path().filename().string())) << e.path();
  std::filesystem::remove_all(dir / "b.csv");
  const auto paths = WriteRuns(dir, runs, {"test"});
  ASSERT_EQ(paths.size(), 2u);
  EXPECT_EQ(ReadRun(paths[1], RunState::kIdle).temperature_C(0, 0), 22.0);
  std::filesystem::remove_all(dir);
}

// A log with `starts` machine starts: spindle_rpm 0 then 1000 per start, `rows_per_run` rows each.
std::string LogWithStarts(int starts, int rows_per_run) {
  std::string text = "time_min,a_C,spindle_rpm\n";
  int row = 0;
  for (int k = 0; k < starts; ++k)
    for (int i = 0; i < rows_per_run; ++i, ++row)
      text += std::to_string(row) + ",20," + (i == 0 ? "0" : "1000") + "\n";
  return text;
}

// Issue 45 item 4: the runs of a split hold the log once. Each Slice used to copy the whole run
// and shrink it, keeping the whole log's capacity in its time and line vectors: k runs held k
// logs (2,500 runs 156 MB, 10,000 runs 2.3 GB). The vectors' capacity is what they hold.
TEST(RunFile, SplitRunsHoldTheLogOnce) {
  const drift::Run log = ParseRun(LogWithStarts(400, 5), "log.csv", RunState::kUnknown);
  const std::vector<drift::Run> runs = SplitAtStarts(log, "spindle_rpm");
  ASSERT_EQ(runs.size(), 400u);
  std::size_t held = 0, rows = 0;
  for (const drift::Run& r : runs) {
    held += r.time_min.capacity() + r.line_numbers.capacity();
    rows += static_cast<std::size_t>(r.samples());
    EXPECT_EQ(r.temperature_C.rows(), r.samples());
    EXPECT_EQ(r.other.rows(), r.samples());
  }
  EXPECT_EQ(rows, 2000u);
  EXPECT_LE(held, 2 * 2 * rows) << "time and line vectors of all runs, in elements";
}

// Issue 45 items 4 and 7: more machine starts than kMaxSplitRuns is an error naming the file, the
// column and the count (a --threshold below the column's idle noise), not 10,000+ files.
TEST(RunFile, SplitRefusesMoreRunsThanTheBound) {
  const drift::Run ok = ParseRun(LogWithStarts(kMaxSplitRuns, 2), "log.csv", RunState::kUnknown);
  EXPECT_EQ(SplitAtStarts(ok, "spindle_rpm").size(), static_cast<std::size_t>(kMaxSplitRuns));
  const drift::Run log = ParseRun(LogWithStarts(kMaxSplitRuns + 1, 2), "log.csv", RunState::kUnknown);
  try {
    SplitAtStarts(log, "spindle_rpm");
    ADD_FAILURE() << "10001 runs accepted";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("log.csv"), std::string::npos) << m;
    EXPECT_NE(m.find("spindle_rpm"), std::string::npos) << m;
    EXPECT_NE(m.find(std::to_string(kMaxSplitRuns + 1)), std::string::npos) << m;
  }
}

// Issue 45 item 7: times of 1e300 min were accepted and written back; every time and every other
// column is bounded, the message naming file, line, column and rule. Minutes since 1970 pass.
TEST(RunFile, TimesAndOtherColumnsAreBounded) {
  for (const std::string& text :
       {std::string("time_min,a_C\n0,20\n1e300,21\n"), std::string("time_min,a_C\n-1e9,20\n0,21\n"),
        std::string("time_s,a_C\n0,20\n7e9,21\n"),
        std::string("time_min,a_C,spindle_rpm\n0,20,0\n1,21,1e300\n")}) {
    const std::string e = ErrorOf(text);
    EXPECT_NE(e.find("r.csv:"), std::string::npos) << text << e;
    EXPECT_NE(e.find("column '"), std::string::npos) << e;
    EXPECT_NE(e.find("outside"), std::string::npos) << e;
  }
  EXPECT_EQ(ErrorOf("time_min,a_C\n29000000,20\n29000001,21\n"), "") << "minutes since 1970";
  EXPECT_EQ(ErrorOf("time_s,a_C\n1700000000,20\n1700000060,21\n"), "") << "seconds since 1970";
}

}  // namespace
}  // namespace whirl::drift
