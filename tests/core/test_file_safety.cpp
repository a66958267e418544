// Files a shop can trust (issue 17): the atomic writer replaces only regular files, multi-file
// outputs are all-or-nothing, readers refuse FIFOs, directories and oversized files, and a JSON
// number beyond the double range is an InputError naming the file.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <string>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/run_program.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

fs::path Scratch(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("whirl_test_file_safety_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

int CountEntries(const fs::path& d) {
  int n = 0;
  for (const auto& e : fs::directory_iterator(d)) (void)e, ++n;
  return n;
}

TEST(AtomicFile, RefusesASymlinkAndLeavesItAndItsTarget) {
  const fs::path d = Scratch("symlink");
  WriteFileAtomic(d / "target.txt", "keep");
  fs::create_symlink(d / "target.txt", d / "link.txt");
  const std::string e = ErrorOf([&] { WriteFileAtomic(d / "link.txt", "new"); });
  EXPECT_NE(e.find("symbolic link"), std::string::npos) << e;
  EXPECT_NE(e.find("link.txt"), std::string::npos) << e;
  EXPECT_TRUE(fs::is_symlink(d / "link.txt"));
  EXPECT_EQ(ReadTextFile(d / "target.txt"), "keep");
  EXPECT_EQ(CountEntries(d), 2);
}

TEST(AtomicFile, RefusesAFifoWithoutBlocking) {
  const fs::path d = Scratch("fifo");
  ASSERT_EQ(::mkfifo((d / "pipe").c_str(), 0600), 0);
  const std::string e = ErrorOf([&] { WriteFileAtomic(d / "pipe", "x"); });
  EXPECT_NE(e.find("FIFO"), std::string::npos) << e;
  EXPECT_TRUE(fs::is_fifo(d / "pipe"));
  const std::string r = ErrorOf([&] { ReadTextFile(d / "pipe"); });
  EXPECT_NE(r.find("FIFO"), std::string::npos) << r;
  EXPECT_EQ(CountEntries(d), 1);
}

TEST(AtomicFile, RefusesADirectoryWithAClearMessage) {
  const fs::path d = Scratch("dir");
  fs::create_directories(d / "existing_dir");
  const std::string e = ErrorOf([&] { WriteFileAtomic(d / "existing_dir", "x"); });
  EXPECT_NE(e.find("is a directory"), std::string::npos) << e;
  EXPECT_EQ(e.find("Success"), std::string::npos) << e;
  EXPECT_TRUE(fs::is_directory(d / "existing_dir"));
  EXPECT_NE(ErrorOf([&] { ReadTextFile(d / "existing_dir"); }).find("directory"),
            std::string::npos);
  EXPECT_EQ(CountEntries(d), 1);
}

TEST(AtomicFile, ManyFilesAreAllOrNothing) {
  const fs::path d = Scratch("many");
  WriteFileAtomic(d / "a.json", "old a");
  fs::create_directories(d / "blocked");
  // The third target is a directory: nothing is written, the old file stays, no temporary left.
  const std::string e = ErrorOf([&] {
    WriteFilesAtomic({{d / "a.json", "new a"}, {d / "b.csv", "new b"}, {d / "blocked", "c"}});
  });
  EXPECT_NE(e.find("blocked"), std::string::npos) << e;
  EXPECT_EQ(ReadTextFile(d / "a.json"), "old a");
  EXPECT_FALSE(fs::exists(d / "b.csv"));
  EXPECT_EQ(CountEntries(d), 2);
  // A missing directory for one of them: the same.
  EXPECT_THROW(WriteFilesAtomic({{d / "a.json", "new a"}, {d / "nodir" / "x", "x"}}), InputError);
  EXPECT_EQ(ReadTextFile(d / "a.json"), "old a");
  EXPECT_EQ(CountEntries(d), 2);
  // The same path twice is refused.
  EXPECT_THROW(WriteFilesAtomic({{d / "a.json", "1"}, {d / "." / "a.json", "2"}}), InputError);
  // All good: all written, no temporary or backup left.
  WriteFilesAtomic({{d / "a.json", "new a"}, {d / "b.csv", "new b"}});
  EXPECT_EQ(ReadTextFile(d / "a.json"), "new a");
  EXPECT_EQ(ReadTextFile(d / "b.csv"), "new b");
  EXPECT_EQ(CountEntries(d), 3);
}

TEST(AtomicFile, ReaderRefusesAnOversizedFile) {
  const fs::path d = Scratch("big");
  const fs::path big = d / "big.csv";
  WriteFileAtomic(big, "a\n");
  fs::resize_file(big, kMaxInputFileBytes + 1);  // sparse: costs no disk
  const std::string e = ErrorOf([&] { ReadTextFile(big); });
  EXPECT_NE(e.find("64 MiB"), std::string::npos) << e;
  EXPECT_NE(e.find("big.csv"), std::string::npos) << e;
}

TEST(JsonFile, NumberBeyondDoubleIsAnInputErrorNamingTheFile) {
  const fs::path d = Scratch("json");
  WriteFileAtomic(d / "huge.json", "{\"length_mm\": 1e400}");
  const std::string e = ErrorOf([&] { ReadJsonFile(d / "huge.json"); });
  EXPECT_NE(e.find("huge.json"), std::string::npos) << e;
  EXPECT_NE(e.find("double range"), std::string::npos) << e;
}

TEST(Csv, CommentWithANewlineStaysOneCommentLine) {
  const std::string text = FormatCsv({"a"}, {{1}}, {"screw 'x\nb\r,c'"});
  const CsvTable t = ParseCsv(text, "t");
  ASSERT_EQ(t.header.size(), 1u);
  EXPECT_EQ(t.header[0], "a");
  ASSERT_EQ(t.rows.size(), 1u);
  EXPECT_EQ(t.comments.size(), 1u);
}

TEST(RunProgram, RelativeLogIsRelativeToTheCallerNotToCwd) {
  const fs::path d = Scratch("run");
  fs::create_directories(d / "sub");
  const fs::path before = fs::current_path();
  fs::current_path(d);
  const int rc = RunProgram({"pwd"}, "sub", "log.txt");
  fs::current_path(before);
  EXPECT_EQ(rc, 0);
  ASSERT_TRUE(fs::exists(d / "log.txt"));
  EXPECT_NE(ReadTextFile(d / "log.txt").find("/sub"), std::string::npos);
}

}  // namespace
}  // namespace whirl
