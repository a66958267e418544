// Files a shop can trust: the atomic writer replaces only regular files, multi-file
// outputs are all-or-nothing, readers refuse FIFOs, directories and oversized files, and a JSON
// number beyond the double range is an InputError naming the file. Where whirl writes: killed
// runs' temporaries are recognised and removed later, output directories follow one rule
// (core/output_dir.h), and outputs that resolve to an input or to another output are refused.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/output_dir.h"
#include "core/run_program.h"
#include "support/expect_error.h"
#include "support/scratch_dir.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

fs::path Scratch(const std::string& name) {
  const fs::path d = whirl::test::ScratchDir() / ("whirl_test_file_safety_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
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

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

std::set<std::string> Entries(const fs::path& d) {
  std::set<std::string> s;
  for (const auto& e : fs::directory_iterator(d)) s.insert(e.path().filename().string());
  return s;
}

// The id of a process that has ended (forked, exited, reaped).
long DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

void Write(OutputDir& out, const std::vector<std::string>& names) {
  for (const auto& n : names) out.Add(n, "text of " + n);
  out.Commit();
}

TEST(WhirlTemporary, NamesAreRecognisedAndCarryThePid) {
  long pid = 0;
  const std::string tmp = WhirlTemporaryName("runs_1.csv", ".whirl-tmp-");
  EXPECT_TRUE(IsWhirlTemporary(tmp, &pid)) << tmp;
  EXPECT_EQ(pid, static_cast<long>(::getpid()));
  EXPECT_EQ(tmp.rfind(".runs_1.csv.whirl-tmp-", 0), 0u) << tmp;
  EXPECT_TRUE(IsWhirlTemporary(WhirlTemporaryName("a", ".whirl-bak-")));
  EXPECT_TRUE(IsWhirlTemporary(WhirlTemporaryName("", "")));  // a staging folder
  for (const std::string name :
       {"runs_1.csv", ".whirl-tmp-1-2", ".a.whirl-tmp-x-2", ".a.whirl-tmp-1-", ".a.whirl-tmp-1-2x",
        "a.whirl-tmp-1-2", ".whirl-stage-1", ".a.tmp12_3"})
    EXPECT_FALSE(IsWhirlTemporary(name)) << name;
}

TEST(WhirlTemporary, WriteRemovesWhatAKilledRunLeftButNotALiveRunsFiles) {
  const fs::path d = Scratch("out_debris");
  const std::string dead = ".a.csv.whirl-tmp-" + std::to_string(DeadPid()) + "-7";
  const std::string live = ".a.csv.whirl-tmp-" + std::to_string(::getpid()) + "-8";
  const std::string other = ".b.csv.whirl-tmp-" + std::to_string(DeadPid()) + "-9";
  for (const auto& n : {dead, live, other}) WriteFileAtomic(d / n, "half");
  WriteFileAtomic(d / "a.csv", "new");
  EXPECT_EQ(Entries(d), (std::set<std::string>{"a.csv", live, other}));  // only a.csv's dead one
}

TEST(OutputDir, NewDirectoryIsCreatedAndListedInTheManifest) {
  const fs::path d = Scratch("out_new") / "sub" / "out";
  OutputDir out(d, "--out-dir");
  EXPECT_FALSE(fs::exists(d));  // nothing before Commit
  Write(out, {"a.csv", "b.csv"});
  EXPECT_EQ(Entries(d), (std::set<std::string>{"a.csv", "b.csv", kOutputManifest}));
  EXPECT_EQ(ReadTextFile(d / "a.csv"), "text of a.csv");
}

TEST(OutputDir, RerunReplacesAndRemovesWhatItNoLongerWrites) {
  const fs::path d = Scratch("out_rerun") / "out";
  {
    OutputDir out(d, "--out-dir");
    Write(out, {"log_1.csv", "log_2.csv", "log_3.csv"});
  }
  OutputDir again(d, "--out-dir");
  again.Add("log_1.csv", "new 1");
  again.Add("log_2.csv", "new 2");
  again.Commit();
  EXPECT_EQ(Entries(d), (std::set<std::string>{"log_1.csv", "log_2.csv", kOutputManifest}));
  EXPECT_EQ(ReadTextFile(d / "log_2.csv"), "new 2");
  OutputDir third(d, "--out-dir");  // and a third time
  Write(third, {"log_1.csv"});
}

TEST(OutputDir, EmptyDirectoryIsAcceptedAForeignFileRefusedByName) {
  const fs::path d = Scratch("out_foreign");
  OutputDir empty(d, "--out-dir");
  Write(empty, {"a.csv"});
  WriteFileAtomic(d / "notes.txt", "mine");
  const std::string e = ErrorOf([&] { OutputDir out(d, "--report"); });
  EXPECT_TRUE(Has(e, "--report")) << e;
  EXPECT_TRUE(Has(e, d.string())) << e;
  EXPECT_TRUE(Has(e, "notes.txt")) << e;
  const fs::path other = Scratch("out_foreign_nomanifest");
  WriteFileAtomic(other / "thesis.tex", "mine");
  const std::string e2 = ErrorOf([&] { OutputDir out(other, "--out-dir"); });
  EXPECT_TRUE(Has(e2, "thesis.tex") && Has(e2, "did not write")) << e2;
  // One sentence: "holds 'thesis.tex', which whirl did not write (...)", not "... write it".
  EXPECT_TRUE(Has(e2, "which whirl did not write (")) << e2;
  EXPECT_EQ(ReadTextFile(other / "thesis.tex"), "mine");
}

TEST(OutputDir, SymlinkedDirectoryIsRefusedAndLeftAlone) {
  const fs::path d = Scratch("out_symlink");
  fs::create_directories(d / "real");
  fs::create_directory_symlink(d / "real", d / "link");
  for (const fs::path& p : {d / "link", fs::path((d / "link").string() + "/")}) {
    const std::string e = ErrorOf([&] { OutputDir out(p, "--out"); });
    EXPECT_TRUE(Has(e, "symbolic link") && Has(e, "--out")) << e;
  }
  EXPECT_TRUE(Entries(d / "real").empty());
  WriteFileAtomic(d / "file", "x");
  EXPECT_TRUE(Has(ErrorOf([&] { OutputDir out(d / "file", "--out-dir"); }), "not a directory"));
}

TEST(OutputDir, ADirectoryAtOneTargetWritesNothing) {
  const fs::path d = Scratch("out_dir_target");
  {
    OutputDir out(d, "--out-dir");
    Write(out, {"a.csv", "b.csv"});
  }
  fs::remove(d / "b.csv");
  fs::create_directory(d / "b.csv");  // planted where whirl wrote a file: not provably whirl's
  const std::string e = ErrorOf([&] {
    OutputDir out(d, "--out-dir");
    out.Add("a.csv", "new a");
    out.Add("b.csv", "new b");
    out.Commit();
  });
  EXPECT_TRUE(Has(e, "b.csv") && Has(e, "a directory")) << e;
  EXPECT_EQ(ReadTextFile(d / "a.csv"), "text of a.csv");
  EXPECT_EQ(Entries(d), (std::set<std::string>{"a.csv", "b.csv", kOutputManifest}));
}

// A run killed (no destructor, no Commit) while it staged files for a program: forked, so its
// process is gone afterwards, like a kill -9.
// `staged` is what the run did before it was killed (default: staged map.gp, then added map.csv).
fs::path KilledRunsStaging(const fs::path& d,
                           const std::function<void(OutputDir&)>& staged = [](OutputDir& out) {
                             out.Add("map.gp", "plot x");
                             out.Staging();
                             out.Add("map.csv", "1,2\n");
                           }) {
  const pid_t child = ::fork();
  if (child == 0) {
    try {
      OutputDir out(d, "--out-dir");
      staged(out);
      ::_exit(0);  // no destructor: what a kill -9 leaves
    } catch (...) {
      ::_exit(1);
    }
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0);
  for (const auto& e : fs::directory_iterator(d))
    if (e.path().filename().string().rfind(".whirl-stage-", 0) == 0) return e.path();
  ADD_FAILURE() << "the killed run left no staging folder";
  return {};
}

TEST(OutputDir, KilledRunsDebrisIsIgnoredAndRemoved) {
  const fs::path d = Scratch("out_killed");
  const fs::path stage = KilledRunsStaging(d);
  EXPECT_EQ(Entries(stage), (std::set<std::string>{kStagingRecord, "map.gp", "map.csv"}));
  const std::string pid = std::to_string(DeadPid());
  WriteFileAtomic(d / (".a.csv.whirl-tmp-" + pid + "-2"), "half");
  WriteFileAtomic(d / (".zz.whirl-bak-" + pid + "-3"), "old");
  OutputDir out(d, "--out-dir");  // only debris: an empty directory
  Write(out, {"a.csv"});
  EXPECT_EQ(Entries(d), (std::set<std::string>{"a.csv", kOutputManifest}));
}

// A run killed while gnuplot wrote into its staging folder: the program's log and picture were
// named in the record before it started (RunInStaging), so the next run removes them; a file the
// program was not told to write still refuses the directory.
TEST(OutputDir, AKilledProgramsNamedOutputsAreWhirlsAndNothingElse) {
  const fs::path d = Scratch("out_killed_program");
  const auto killed_while_program_ran = [&] {
    return KilledRunsStaging(d, [](OutputDir& out) {
      out.Add("map.gp", "plot x");
      out.RunInStaging({"/bin/sh", "-c", "printf png > map.png; echo started"}, "gnuplot.log",
                       {"map.png"});
    });
  };
  const fs::path stage = killed_while_program_ran();
  EXPECT_EQ(Entries(stage),
            (std::set<std::string>{kStagingRecord, "map.gp", "map.png", "gnuplot.log"}));
  {
    OutputDir out(d, "--out-dir");
    Write(out, {"a.csv"});
  }
  EXPECT_EQ(Entries(d), (std::set<std::string>{"a.csv", kOutputManifest}));
  fs::remove_all(d);
  const fs::path again = killed_while_program_ran();
  WriteFileAtomic(again / "other.png", "not named");
  const std::string e = ErrorOf([&] { OutputDir out(d, "--out-dir"); });
  EXPECT_TRUE(Has(e, "other.png")) << e;
  EXPECT_EQ(ReadTextFile(again / "map.png"), "png");
}

// Issue 45 item 6: a folder named like a killed run's staging folder, holding a user's file, is
// neither deleted nor emptied: whirl refuses the directory and names the file.
TEST(OutputDir, AStagingNamedFolderWithAUsersFileIsLeftAlone) {
  const fs::path d = Scratch("out_fake_stage");
  const fs::path fake = d / ".whirl-stage-999999-0";
  fs::create_directories(fake);
  WriteFileAtomic(fake / "thesis.tex", "mine");
  const std::string e = ErrorOf([&] {
    OutputDir out(d, "--out-dir");
    Write(out, {"a.csv"});
  });
  EXPECT_TRUE(Has(e, ".whirl-stage-999999-0") && Has(e, "thesis.tex")) << e;
  EXPECT_EQ(ReadTextFile(fake / "thesis.tex"), "mine");
  // And a user's file put into a killed run's real staging folder: its recorded files are all
  // whirl may remove, so the folder stays, named, with everything in it.
  fs::remove_all(fake);
  const fs::path stage = KilledRunsStaging(d);
  WriteFileAtomic(stage / "notes.txt", "mine too");
  const std::string e2 = ErrorOf([&] { OutputDir out(d, "--out-dir"); });
  EXPECT_TRUE(Has(e2, "notes.txt")) << e2;
  EXPECT_EQ(ReadTextFile(stage / "notes.txt"), "mine too");
  EXPECT_TRUE(fs::exists(stage / "map.gp"));
}

// Issue 45 item 6: a forged manifest listing a user's file does not make whirl delete or replace
// it: the manifest proves a file only by the SHA-256 of its content.
TEST(OutputDir, AForgedManifestCannotMakeWhirlDeleteAFile) {
  const fs::path d = Scratch("out_forged");
  WriteFileAtomic(d / "notes.txt", "my notes");
  for (const std::string& manifest :
       {std::string(R"({"schema": "whirl.output_dir", "files": ["notes.txt"]})"),
        std::string(R"({"schema": "whirl.output_dir", "schema_version": 2, "files": )"
                    R"([{"name": "notes.txt", "sha256": ")") +
            std::string(64, '0') + "\"}]}"}) {
    WriteFileAtomic(d / kOutputManifest, manifest);
    for (bool rewrite : {false, true}) {
      const std::string e = ErrorOf([&] {
        OutputDir out(d, "--out-dir");
        Write(out, {rewrite ? "notes.txt" : "sensors.csv"});
      });
      EXPECT_TRUE(Has(e, "notes.txt")) << e;
      EXPECT_EQ(ReadTextFile(d / "notes.txt"), "my notes");
    }
  }
}

// A file whirl wrote and the user changed afterwards is the user's now: refused by name, kept.
TEST(OutputDir, AFileChangedSinceWhirlWroteItIsRefusedAndKept) {
  const fs::path d = Scratch("out_changed");
  {
    OutputDir out(d, "--out-dir");
    Write(out, {"a.csv", "b.csv"});
  }
  WriteFileAtomic(d / "b.csv", "edited in a spreadsheet");
  const std::string e = ErrorOf([&] {
    OutputDir out(d, "--out-dir");
    Write(out, {"a.csv"});  // b.csv would be removed as no longer written
  });
  EXPECT_TRUE(Has(e, "b.csv") && Has(e, "changed since")) << e;
  EXPECT_EQ(ReadTextFile(d / "b.csv"), "edited in a spreadsheet");
}

// Issue 44 item 10: a foreign sub-directory in an output directory refuses it and stays, with or
// without a manifest of its own that does not prove its content.
TEST(OutputDir, AForeignSubDirectoryIsRefusedAndLeftAlone) {
  const fs::path d = Scratch("out_foreign_sub");
  {
    OutputDir out(d, "--out-dir");
    Write(out, {"a.csv"});
  }
  fs::create_directories(d / "photos");
  WriteFileAtomic(d / "photos" / "screw.jpg", "jpeg");
  for (const std::string manifest :
       {"", R"({"schema": "whirl.output_dir", "files": ["screw.jpg"]})"}) {
    if (!manifest.empty()) WriteFileAtomic(d / "photos" / kOutputManifest, manifest);
    const std::string e = ErrorOf([&] {
      OutputDir out(d, "--out-dir");
      Write(out, {"a.csv"});
    });
    EXPECT_TRUE(Has(e, "photos")) << e;
    EXPECT_EQ(ReadTextFile(d / "photos" / "screw.jpg"), "jpeg");
  }
}

// The manifest's hash is SHA-256 (FIPS 180-4 test vectors: "abc", and 56 bytes over two blocks).
TEST(OutputDir, TheManifestListsTheSha256OfEachFile) {
  const fs::path d = Scratch("out_sha");
  OutputDir out(d, "--out-dir");
  out.Add("abc", "abc");
  out.Add("two_blocks", "abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq");
  out.Add("empty", "");
  out.Commit();
  const nlohmann::json m = ReadJsonFile(d / kOutputManifest);
  std::map<std::string, std::string> hash;
  for (const auto& f : m.at("files")) hash[f.at("name")] = f.at("sha256");
  EXPECT_EQ(hash["abc"], "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(hash["two_blocks"],
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(hash["empty"], "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
}

TEST(OutputDir, FailureBeforeCommitLeavesNoDirectory) {
  const fs::path d = Scratch("out_fail") / "out";
  {
    OutputDir out(d, "--report");
    out.Add("a.csv", "x");
    ASSERT_TRUE(fs::is_directory(out.Staging()));
  }  // an exception would leave here without Commit
  EXPECT_FALSE(fs::exists(d));
}

TEST(OutputDir, StagingHoldsTheFilesForAProgramAndTakesItsOutput) {
  const fs::path d = Scratch("out_staging");
  OutputDir out(d, "--report");
  out.Add("data.csv", "1,2\n");
  const fs::path s = out.Staging();
  out.Add("plot.gp", "plot 'data.csv'\n");
  EXPECT_EQ(ReadTextFile(s / "data.csv"), "1,2\n");
  EXPECT_EQ(ReadTextFile(s / "plot.gp"), "plot 'data.csv'\n");
  WriteFileAtomic(s / "plot.png", std::string("\x89PNG\0\x01", 6));  // what gnuplot would write
  out.AddStaged("plot.png");
  out.Commit();
  EXPECT_EQ(ReadTextFile(d / "plot.png"), std::string("\x89PNG\0\x01", 6));
  EXPECT_EQ(Entries(d).size(), 4u);  // data.csv, plot.gp, plot.png, manifest; staging is gone
}

TEST(OutputDir, NestedWhirlDirectoryCountsAsWhirls) {
  const fs::path d = Scratch("out_nested");
  {
    OutputDir report(d / "report", "report directory");
    Write(report, {"index.html"});
  }  // a parent killed before its own commit: only the nested output exists
  OutputDir out(d, "--out-dir");
  out.Keep("report");
  Write(out, {"plan.json"});
  EXPECT_EQ(Entries(d), (std::set<std::string>{"plan.json", "report", kOutputManifest}));
  OutputDir again(d, "--out-dir");  // a rerun without the report removes it through its manifest
  Write(again, {"plan.json"});
  EXPECT_EQ(Entries(d), (std::set<std::string>{"plan.json", kOutputManifest}));
}

TEST(OutputDir, ABrokenManifestIsRefusedByName) {
  const fs::path d = Scratch("out_badmanifest");
  WriteFileAtomic(d / kOutputManifest, "{\"schema\": \"whirl.output_dir\", \"files\": [\"../x\"]}");
  const std::string e = ErrorOf([&] { OutputDir out(d, "--out-dir"); });
  EXPECT_TRUE(Has(e, kOutputManifest) && Has(e, "not a whirl output manifest")) << e;
}

TEST(CheckOutputs, OutputThatIsAnInputIsRefusedThroughDotSlashLinksAndHardLinks) {
  const fs::path d = Scratch("out_same");
  WriteFileAtomic(d / "run.csv", "data");
  fs::create_symlink(d / "run.csv", d / "alias.csv");
  fs::create_hard_link(d / "run.csv", d / "hard.csv");
  fs::create_directories(d / "sub");
  const std::vector<FlagPath> in{{"--model", d / "model.json"}, {"--run", d / "run.csv"}};
  for (const fs::path& out :
       {d / "." / "run.csv", d / "sub" / ".." / "run.csv", d / "alias.csv", d / "hard.csv"}) {
    const std::string e = ErrorOf([&] { CheckOutputs(in, {{"--out", out}}); });
    EXPECT_TRUE(Has(e, "--out") && Has(e, "--run") && Has(e, out.string())) << out << ": " << e;
  }
  EXPECT_EQ(ReadTextFile(d / "run.csv"), "data");
  CheckOutputs(in, {{"--out", d / "pred.csv"}, {"--csv", {}}});  // different or not given: fine
}

TEST(CheckOutputs, RelativeOutputAgainstAnAbsoluteInput) {
  const fs::path d = Scratch("out_relative");
  WriteFileAtomic(d / "m.json", "{}");
  const fs::path cwd = fs::current_path();
  fs::current_path(d);
  const std::string e = ErrorOf([&] {
    CheckOutputs({{"--model", d / "m.json"}}, {{"--csv", "./m.json"}});
  });
  fs::current_path(cwd);
  EXPECT_TRUE(Has(e, "--csv") && Has(e, "--model")) << e;
}

TEST(CheckOutputs, TwoOutputsOneFileAndOutputsInsideOutputDirectories) {
  const fs::path d = Scratch("out_outs");
  fs::current_path(d);
  std::string e = ErrorOf([&] {
    CheckOutputs({}, {{"--nc", "A.SPF"}, {"--reset-nc", "./A.SPF"}});
  });
  EXPECT_TRUE(Has(e, "--nc") && Has(e, "--reset-nc") && Has(e, "same file")) << e;
  e = ErrorOf([&] { CheckOutputs({}, {{"--out", "rep/b.json"}}, {{"--report", "rep"}}); });
  EXPECT_TRUE(Has(e, "--out") && Has(e, "--report")) << e;
  WriteFileAtomic(d / "log.csv", "x");
  e = ErrorOf([&] { CheckOutputs({{"--log", "log.csv"}}, {}, {{"--out-dir", "."}}); });
  EXPECT_TRUE(Has(e, "--log") && Has(e, "--out-dir") && Has(e, "holds the input")) << e;
  e = ErrorOf([&] { CheckOutputs({}, {}, {{"--report", "a"}, {"--out-dir", "a/b"}}); });
  EXPECT_TRUE(Has(e, "--report") && Has(e, "--out-dir")) << e;
  fs::create_directory(d / "adir");
  e = ErrorOf([&] { CheckOutputs({}, {{"--timeline", "adir"}}); });
  EXPECT_TRUE(Has(e, "--timeline") && Has(e, "a directory")) << e;
  fs::current_path(whirl::test::ScratchDir());
}

}  // namespace
}  // namespace whirl
