#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace whirl {

/// Largest input file whirl reads whole into memory [bytes] (ReadTextFile: process tables, models,
/// screws, profiles, surfaces): 64 MiB, far above any of them (the shipped 500-row table is about
/// 60 kB), so a wrong path cannot exhaust memory. Run files and logs of the drift commands are
/// not read whole: core/csv.h's CsvReader streams them, and drift/run_file.h states their limits.
inline constexpr std::uintmax_t kMaxInputFileBytes = 64ull << 20;

/// Writes `contents` to `path` atomically: into a temporary file in the same directory, flushed,
/// then renamed over `path`. A failure (disk full, missing directory, interrupted run) leaves any
/// previous file untouched and no half-written file behind. The target must be absent or a
/// regular file: a symbolic link, directory, FIFO, socket or device node at `path` is refused
/// (InputError naming the path and what it is) and left untouched. Throws InputError naming the
/// path on any failure.
void WriteFileAtomic(const std::filesystem::path& path, const std::string& contents);

/// Writes several files all-or-nothing: every target is checked (as WriteFileAtomic, and no path
/// twice) before anything is written, every file is written to a temporary beside its target, and
/// only then are they renamed over the targets. A failure in any step removes every temporary; a
/// rename failing after others succeeded puts the previous files back (from hard-linked backups).
/// Throws InputError.
///
/// What a killed process (kill -9, power loss) leaves: never a half-written target, only hidden
/// temporaries beside the targets, named so they are recognisably whirl's (see IsWhirlTemporary):
/// ".<target>.whirl-tmp-<pid>-<n>" while a file is written, ".<target>.whirl-bak-<pid>-<n>" (a hard
/// link to the previous file) while several are renamed. Killed in the renaming step, which takes
/// microseconds, some targets may be new and others old. The next write of the same target removes
/// the temporaries of processes that no longer run (RemoveStaleTemporaries), and an output
/// directory (core/output_dir.h) removes all of them; a running process's temporaries are left.
void WriteFilesAtomic(const std::vector<std::pair<std::filesystem::path, std::string>>& files);

/// A file of WriteFilesAtomic whose contents are already on disk (a long output written with
/// StreamedFile and finished): `ready`, a complete file on the same file system as `path`, is
/// renamed over `path` in the same all-or-nothing step instead of being copied.
struct ReadyFile {
  std::filesystem::path path;   ///< the target
  std::filesystem::path ready;  ///< the finished file (removed when the write fails)
};
/// WriteFilesAtomic with some files already on disk.
void WriteFilesAtomic(const std::vector<std::pair<std::filesystem::path, std::string>>& files,
                      const std::vector<ReadyFile>& ready);

/// A file written piece by piece without holding it (a per-sample output of a long log): the
/// text goes through a 1 MiB buffer into a temporary beside `path` (named as WriteFileAtomic's);
/// Commit() flushes it to disk and renames it over `path`, Finish() flushes it and hands it over
/// (for WriteFilesAtomic's ReadyFile). Destroyed before either (an error on the way), it removes
/// the temporary and leaves `path` as it was. The target follows CheckOutputFile's rule (checked
/// when opened); InputError naming the path on any failure.
class StreamedFile {
 public:
  explicit StreamedFile(std::filesystem::path path);
  ~StreamedFile();
  StreamedFile(const StreamedFile&) = delete;
  StreamedFile& operator=(const StreamedFile&) = delete;

  const std::filesystem::path& path() const { return path_; }
  void Append(std::string_view text);
  /// Appends the bytes of another file.
  void AppendFile(const std::filesystem::path& other);
  /// Flushes and closes the temporary and returns it; the caller renames or removes it.
  /// `durable` false: no fsync (a scratch file that never becomes an output).
  std::filesystem::path Finish(bool durable = true);
  /// Finish, then rename over path().
  void Commit();

 private:
  void Flush();
  std::filesystem::path path_, tmp_;
  std::string buffer_;
  int fd_ = -1;
  bool handed_over_ = false;
};

/// The writer's rule for one target, checked without writing (for checks before a long run):
/// `path` names a file (not a directory path), its directory exists, and it is absent or a regular
/// file. Throws the InputError WriteFileAtomic would, naming the path and what it is.
void CheckOutputFile(const std::filesystem::path& path);

/// The name of a new whirl temporary for `base` (a file name without directory):
/// "." + base + kind + "<pid>-<n>", kind one of ".whirl-tmp-", ".whirl-bak-"; with an empty
/// `base`, ".whirl-stage-<pid>-<n>" (the staging folder of an output directory).
std::string WhirlTemporaryName(const std::string& base, const char* kind);

/// True when the file name `name` (no directory) is one of whirl's temporaries (see
/// WhirlTemporaryName); `pid` (optional) receives the id of the process that made it.
bool IsWhirlTemporary(const std::string& name, long* pid = nullptr);

/// Removes from `dir` the whirl file temporaries whose process no longer runs; with `target` (a
/// file name), only those of that target. Staging folders are left to core/output_dir.h (it
/// removes only what their record proves). Never follows a symbolic link and never throws (what
/// cannot be removed stays).
void RemoveStaleTemporaries(const std::filesystem::path& dir, const std::string& target = "");

/// Reads a whole text file; throws InputError naming the path if it cannot be opened, is not a
/// regular file (a FIFO, device or directory) or is larger than kMaxInputFileBytes.
std::string ReadTextFile(const std::filesystem::path& path);

/// The rule of every input file, checked before it is opened: it exists and is a regular file (a
/// FIFO or a device would block or never end, a directory has no text). Returns its size
/// [bytes]; InputError naming the path otherwise ("cannot open", "cannot read ... it is a FIFO").
std::uintmax_t CheckInputFile(const std::filesystem::path& path);

}  // namespace whirl
