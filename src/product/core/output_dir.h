#pragma once
// Where whirl writes: the one rule for output directories (--out-dir, --report, --curves-dir, ...)
// and the check that no output lands on one of the command's inputs or on another output. Every
// command with a directory output writes it through OutputDir; every command with inputs and
// outputs calls CheckOutputs before it reads or writes anything.
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.h"  // ReadyFile

namespace whirl {

/// The file in each output directory that lists what whirl wrote there: JSON, schema
/// "whirl.output_dir", schema_version 2, key "files" ({"name", "sha256"}: one path component and
/// the SHA-256 of the content whirl wrote) and "directories" (sub-directories written through
/// their own OutputDir, each with its own manifest). A version 1 manifest (names only) still
/// reads, but proves nothing: whirl refuses a directory whose listed files it cannot prove.
inline constexpr const char* kOutputManifest = ".whirl-output.json";
/// The record inside a staging folder (".whirl-stage-<pid>-<n>") of the files whirl put there,
/// with their SHA-256 (schema "whirl.output_dir.staging"), so a later run can remove the folder
/// of a killed run without removing anything else.
inline constexpr const char* kStagingRecord = ".whirl-stage.json";
/// The staging record's "hash" of a file a program run by whirl writes (OutputDir::RunInStaging):
/// its content is not known in advance, its name is.
inline constexpr const char* kProgramOutput = "program-output";

/// The rule below in a few words, for --help texts of directory flags.
inline constexpr const char* kOutputDirRule =
    "a new or empty directory, or one whirl wrote before (its files are replaced); never a "
    "symbolic link";

/// The rule for an output directory `dir`, checked without writing anything. `dir` must be
///  - not a symbolic link (refused even when it points to a directory: a link planted at the path
///    would send the files elsewhere; give the directory itself), and
///  - absent (it is created, with its parents), or an empty directory, or a directory whirl wrote
///    before: one holding kOutputManifest. A file listed there is whirl's only while its content
///    still has the listed SHA-256: a new run replaces such files and removes those it does not
///    write again. A sub-directory is whirl's when it holds its own manifest that proves all of
///    its content likewise (the demo's report/). Anything else in the directory refuses it: a
///    file not listed, a listed file changed since (or listed without a hash, by an older
///    whirl), a foreign sub-directory, a staging folder of a run that is gone holding a file
///    its kStagingRecord does not prove.
/// whirl's file temporaries (core/atomic_file.h IsWhirlTemporary) are ignored, and so is the
/// staging folder of a whirl process that still runs. Throws an InputError naming `what` (the
/// flag, e.g. "--out-dir"), the directory and, when it refuses a directory with foreign content,
/// one such entry and why.
/// Why this rule: running a command again into its own directory must work (`whirl demo --out-dir
/// out` twice) and must not leave files of the earlier run beside the new ones, while whirl must
/// never mix its files with someone else's or delete what it did not write: a forged or copied
/// manifest cannot make whirl delete a file unless it states that file's exact content hash.
void CheckOutputDir(const std::filesystem::path& dir, const std::string& what);

/// An output directory written all-or-nothing. The constructor applies CheckOutputDir and creates
/// nothing; Add collects files in memory; Commit writes them and the manifest in one
/// WriteFilesAtomic (a failure leaves the directory as it was), then removes the files of the
/// previous manifest this run did not write (each only if its content still matches). Without
/// Commit (an exception on the way) the destructor removes the staging folder and the directory
/// itself if this object created it. Killed (kill -9) before Commit, a run leaves the directory
/// as it was plus hidden whirl temporaries (".whirl-stage-<pid>-<n>" with its kStagingRecord);
/// killed inside Commit, see WriteFilesAtomic. The next run ignores them and its Commit removes
/// the files they provably hold (a file a program wrote into the staging folder just before the
/// kill is not yet recorded: the folder then stays and refuses the directory by name).
class OutputDir {
 public:
  OutputDir(std::filesystem::path dir, std::string what);
  ~OutputDir();
  OutputDir(const OutputDir&) = delete;
  OutputDir& operator=(const OutputDir&) = delete;

  const std::filesystem::path& path() const { return dir_; }

  /// Creates the directory (and its parents) unless it exists; returns path().
  const std::filesystem::path& Create();

  /// A file of the output: `name` is one path component (no '/', not the manifest), given once.
  void Add(const std::string& name, std::string contents);

  /// A file of the output already on disk, written without holding it (a long per-sample CSV:
  /// StreamedFile with a target inside Staging(), then Finish()): `ready` is renamed into place
  /// by Commit, never read into memory. Not copied into Staging() under `name`.
  void AddReady(const std::string& name, const std::filesystem::path& ready);

  /// An entry written by its own OutputDir during this run (the demo's report/ sub-directory):
  /// listed in the manifest, never written by Commit.
  void Keep(const std::string& name);

  /// A folder inside the directory (".whirl-stage-<pid>-<n>", created on the first call) holding
  /// a copy of every file added, before and after the call, for a program that reads them and
  /// writes its own files there (gnuplot); removed by Commit or the destructor.
  const std::filesystem::path& Staging();

  /// Adds the file `name` a program wrote into Staging() (binary safe).
  void AddStaged(const std::string& name);

  /// Runs `argv` (e.g. gnuplot) in Staging() with its output and errors in the file `log`
  /// there, and returns its exit status (RunProgram). Before it starts, `log` and `outputs` (the
  /// files the program is told to write) are recorded as the program's in the staging record
  /// (kProgramOutput instead of a hash): if this run is killed while the program runs, the next
  /// run can prove those names are whirl's and remove them. Add what it wrote with AddStaged.
  int RunInStaging(const std::vector<std::string>& argv, const std::string& log,
                   const std::vector<std::string>& outputs);
  /// Adds the log `name` of a RunInStaging program if it wrote one (false if not).
  bool AddProgramLog(const std::string& name);

  /// Writes every added file, the manifest and `also` (files outside the directory, e.g. the
  /// --out JSON beside a --report) all-or-nothing; re-checks the rule first. Returns the paths
  /// of the added files.
  std::vector<std::filesystem::path> Commit(
      const std::vector<std::pair<std::filesystem::path, std::string>>& also = {},
      const std::vector<ReadyFile>& also_ready = {});

 private:
  void Insert(const std::string& name, std::string contents);  // checks the name, keeps it
  // Records `name` with its hash in the staging folder's record (and writes it there if `write`).
  void Stage(const std::string& name, const std::string& contents, bool write);
  void WriteStagingRecord() const;  // staged_ into the staging folder's kStagingRecord

  std::filesystem::path dir_;
  std::string what_;
  std::vector<std::pair<std::string, std::string>> files_;
  std::set<std::string> names_;  ///< of files_
  std::vector<std::string> kept_;
  std::vector<ReadyFile> ready_;  ///< AddReady: the target inside the directory, the file
  std::map<std::string, std::string> ready_hashes_;  ///< AddReady: name -> SHA-256
  std::filesystem::path staging_;
  std::map<std::string, std::string> staged_;  ///< name -> SHA-256 in the staging folder
  bool created_ = false, committed_ = false;
};

/// A path given on the command line and its flag, for messages.
struct FlagPath {
  std::string flag;  ///< e.g. "--run"
  std::filesystem::path path;
};

/// Refuses, before a command reads or writes anything, any output that would overwrite one of its
/// inputs or another output. Paths are compared as canonical absolute paths (through symbolic
/// links, "./" and ".."; an output that does not exist yet by its existing parent) and by device
/// and inode (hard links). Refused, with an InputError naming both flags and the path:
///  - an output file that is an input, or another output file;
///  - an input or an output file inside an output directory (whirl replaces and removes the files
///    it wrote there), or two output directories that are the same or nested.
/// Then each output file must pass CheckOutputFile (core/atomic_file.h) and each output directory
/// CheckOutputDir. Entries with an empty path (flags not given) are skipped.
void CheckOutputs(const std::vector<FlagPath>& inputs, const std::vector<FlagPath>& files,
                  const std::vector<FlagPath>& dirs = {});

}  // namespace whirl
