#include "core/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

#include "core/error.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

constexpr const char* kTmp = ".whirl-tmp-";
constexpr const char* kBak = ".whirl-bak-";
constexpr const char* kStage = ".whirl-stage-";

std::string Quoted(const fs::path& p) { return "'" + p.string() + "'"; }

std::string KindOf(mode_t mode) {
  if (S_ISLNK(mode)) return "a symbolic link";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

fs::path DirectoryOf(const fs::path& path) {
  return path.has_parent_path() ? path.parent_path() : fs::path(".");
}

// The rule of the writer: the target is absent or a regular file, in an existing directory.
void CheckTarget(const fs::path& path) {
  if (path.empty() || !path.has_filename())
    throw InputError("cannot write " + Quoted(path) + ": not a file path");
  const fs::path dir = DirectoryOf(path);
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw InputError("cannot write " + Quoted(path) + ": directory " + Quoted(dir) +
                     " does not exist");
  struct stat st {};
  if (::lstat(path.c_str(), &st) != 0) {
    if (errno == ENOENT) return;
    throw InputError("cannot write " + Quoted(path) + ": " + std::strerror(errno));
  }
  if (!S_ISREG(st.st_mode))
    throw InputError("cannot write " + Quoted(path) + ": it is " + KindOf(st.st_mode) +
                     "; whirl replaces only regular files (choose a file path)");
}

fs::path TemporaryName(const fs::path& path, const char* kind) {
  return DirectoryOf(path) / WhirlTemporaryName(path.filename().string(), kind);
}

// "<digits>-<digits>" and nothing else: the tail of a whirl temporary's name.
bool ParsePidTail(const std::string& tail, long* pid) {
  const auto dash = tail.find('-');
  if (dash == 0 || dash == std::string::npos || dash + 1 == tail.size() || dash > 18) return false;
  for (std::size_t i = 0; i < tail.size(); ++i)
    if (i != dash && !std::isdigit(static_cast<unsigned char>(tail[i]))) return false;
  if (pid) *pid = std::stol(tail.substr(0, dash));
  return true;
}

// A process that no longer runs (kill(pid, 0) fails with ESRCH); EPERM means it runs as another
// user. A reused pid makes a stale temporary look alive: it is then left, never a live one removed.
bool ProcessIsGone(long pid) {
  return pid > 0 && ::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH;
}

// A whirl temporary's target file name ("" for a staging folder) and process id; false when
// `name` is not a whirl temporary.
bool ParseTemporary(const std::string& name, std::string* target, long* pid) {
  const std::string stage = kStage;
  if (name.compare(0, stage.size(), stage) == 0) {
    if (target) target->clear();
    return ParsePidTail(name.substr(stage.size()), pid);
  }
  if (name.size() < 2 || name[0] != '.') return false;
  for (const std::string kind : {kTmp, kBak}) {
    const auto at = name.rfind(kind);
    if (at != std::string::npos && at > 1 && ParsePidTail(name.substr(at + kind.size()), pid)) {
      if (target) *target = name.substr(1, at - 1);
      return true;
    }
  }
  return false;
}

// Removes the file temporaries in `dir` whose process is gone: all (`targets` null) or those of
// the named targets. One pass over the directory. Staging folders (and anything named like one)
// are left to core/output_dir.h, which removes only what their record proves whirl put there.
void RemoveStale(const fs::path& dir, const std::set<std::string>* targets) {
  std::error_code ec;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    std::string target;
    long pid = 0;
    if (!ParseTemporary(it->path().filename().string(), &target, &pid) || target.empty() ||
        !ProcessIsGone(pid) || (targets && targets->count(target) == 0))
      continue;
    std::error_code rm;
    if (!fs::is_directory(it->symlink_status(rm)))
      fs::remove(it->path(), rm);  // a file, or a link itself (never what it points to)
  }
}

// Writes `contents` to a new temporary file beside `path`, flushed to disk; returns its name.
fs::path WriteTemporary(const fs::path& path, const std::string& contents) {
  const fs::path tmp = TemporaryName(path, kTmp);
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd < 0) throw InputError("cannot write " + Quoted(path) + ": " + std::strerror(errno));
  std::size_t off = 0;
  int err = 0;
  while (off < contents.size()) {
    const ssize_t n = ::write(fd, contents.data() + off, contents.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      err = n < 0 ? errno : ENOSPC;
      break;
    }
    off += static_cast<std::size_t>(n);
  }
  if (err == 0 && ::fsync(fd) != 0) err = errno;
  if (::close(fd) != 0 && err == 0) err = errno;
  if (err != 0) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw InputError("cannot write " + Quoted(path) + ": " + std::strerror(err));
  }
  return tmp;
}

void RemoveAll(const std::vector<fs::path>& paths) {
  std::error_code ec;
  for (const auto& p : paths)
    if (!p.empty()) fs::remove(p, ec);
}

}  // namespace

void WriteFileAtomic(const fs::path& path, const std::string& contents) {
  WriteFilesAtomic({{path, contents}});
}

void CheckOutputFile(const fs::path& path) { CheckTarget(path); }

std::string WhirlTemporaryName(const std::string& base, const char* kind) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  const std::string tail = std::to_string(::getpid()) + "-" + std::to_string(rng() >> 16);
  return base.empty() ? kStage + tail : "." + base + kind + tail;
}

bool IsWhirlTemporary(const std::string& name, long* pid) {
  return ParseTemporary(name, nullptr, pid);
}

void RemoveStaleTemporaries(const fs::path& dir, const std::string& target) {
  if (target.empty()) return RemoveStale(dir, nullptr);
  const std::set<std::string> targets{target};
  RemoveStale(dir, &targets);
}

void WriteFilesAtomic(const std::vector<std::pair<fs::path, std::string>>& files) {
  WriteFilesAtomic(files, {});
}

void WriteFilesAtomic(const std::vector<std::pair<fs::path, std::string>>& texts,
                      const std::vector<ReadyFile>& ready) {
  std::vector<fs::path> paths;
  for (const auto& [path, text] : texts) paths.push_back(path);
  for (const ReadyFile& r : ready) paths.push_back(r.path);
  std::vector<fs::path> ready_files;
  for (const ReadyFile& r : ready) ready_files.push_back(r.ready);
  try {
    std::set<fs::path> seen;
    for (const auto& path : paths) {
      CheckTarget(path);
      // Absolute first: weakly_canonical leaves a relative path whose parts do not exist yet
      // relative ("A.SPF"), but makes "./A.SPF" absolute, so the two would compare unequal.
      if (!seen.insert(fs::weakly_canonical(fs::absolute(path))).second)
        throw InputError("cannot write " + Quoted(path) + ": the same file is given twice");
    }
  } catch (...) {
    RemoveAll(ready_files);
    throw;
  }
  std::map<fs::path, std::set<std::string>> targets;  // what killed runs left beside them
  for (const auto& path : paths) targets[DirectoryOf(path)].insert(path.filename().string());
  for (const auto& [dir, names] : targets) RemoveStale(dir, &names);
  // 1. Every file into a temporary beside its target (the ready ones are): a failure here leaves
  // nothing behind.
  std::vector<fs::path> tmps;
  try {
    for (const auto& [path, text] : texts) tmps.push_back(WriteTemporary(path, text));
  } catch (...) {
    RemoveAll(tmps);
    RemoveAll(ready_files);
    throw;
  }
  tmps.insert(tmps.end(), ready_files.begin(), ready_files.end());
  // 2. Rename them over the targets; an existing target is hard-linked to a backup first, so a
  // failing rename restores every target already replaced.
  std::vector<fs::path> backups(paths.size());
  std::vector<bool> existed(paths.size(), false);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const fs::path& path = paths[i];
    std::error_code ec;
    existed[i] = fs::is_regular_file(fs::symlink_status(path, ec));
    if (existed[i]) {
      backups[i] = TemporaryName(path, kBak);
      fs::create_hard_link(path, backups[i], ec);
      if (ec) backups[i].clear();  // e.g. a file system without hard links: no restore possible
    }
    fs::rename(tmps[i], path, ec);
    if (!ec) continue;
    const std::string reason = ec.message();
    for (std::size_t k = 0; k < i; ++k) {
      if (!backups[k].empty())
        fs::rename(backups[k], paths[k], ec);
      else if (!existed[k])
        fs::remove(paths[k], ec);
    }
    RemoveAll(tmps);
    RemoveAll(backups);
    throw InputError("cannot write " + Quoted(path) + ": rename failed: " + reason +
                     (i > 0 ? " (the files written before it were restored)" : ""));
  }
  RemoveAll(backups);
}

StreamedFile::StreamedFile(fs::path path) : path_(std::move(path)) {
  CheckTarget(path_);
  tmp_ = TemporaryName(path_, kTmp);
  fd_ = ::open(tmp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0666);
  if (fd_ < 0) throw InputError("cannot write " + Quoted(path_) + ": " + std::strerror(errno));
  buffer_.reserve(1u << 20);
}

StreamedFile::~StreamedFile() {
  if (fd_ >= 0) ::close(fd_);
  if (!handed_over_) {
    std::error_code ec;
    fs::remove(tmp_, ec);
  }
}

void StreamedFile::Flush() {
  std::size_t off = 0;
  while (off < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + off, buffer_.size() - off);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0)
      throw InputError("cannot write " + Quoted(path_) + ": " +
                       std::strerror(n < 0 ? errno : ENOSPC));
    off += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

void StreamedFile::Append(std::string_view text) {
  if (fd_ < 0) throw std::logic_error("StreamedFile::Append after Finish");
  buffer_.append(text);
  if (buffer_.size() >= (1u << 20)) Flush();
}

void StreamedFile::AppendFile(const fs::path& other) {
  const int in = ::open(other.c_str(), O_RDONLY | O_CLOEXEC);
  if (in < 0) throw InputError("cannot read " + Quoted(other) + ": " + std::strerror(errno));
  std::string chunk(1u << 20, '\0');
  for (;;) {
    const ssize_t n = ::read(in, chunk.data(), chunk.size());
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      const int err = errno;
      ::close(in);
      throw InputError("cannot read " + Quoted(other) + ": " + std::strerror(err));
    }
    if (n == 0) break;
    Append(std::string_view(chunk.data(), static_cast<std::size_t>(n)));
  }
  ::close(in);
}

fs::path StreamedFile::Finish(bool durable) {
  Flush();
  int err = durable && ::fsync(fd_) != 0 ? errno : 0;
  if (::close(fd_) != 0 && err == 0) err = errno;
  fd_ = -1;
  if (err != 0) throw InputError("cannot write " + Quoted(path_) + ": " + std::strerror(err));
  handed_over_ = true;
  return tmp_;
}

void StreamedFile::Commit() { WriteFilesAtomic({}, {{path_, Finish()}}); }

std::uintmax_t CheckInputFile(const fs::path& path) {
  // Only regular files: a FIFO or a device would block or never end, a directory has no text.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw InputError("cannot open " + Quoted(path) + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw InputError("cannot read " + Quoted(path) + ": it is " + KindOf(st.st_mode) +
                     "; whirl reads only regular files");
  return static_cast<std::uintmax_t>(st.st_size);
}

std::string ReadTextFile(const fs::path& path) {
  const std::uintmax_t size = CheckInputFile(path);
  if (size > kMaxInputFileBytes)
    throw InputError("cannot read " + Quoted(path) + ": " + std::to_string(size) +
                     " bytes breaks the limit of " + std::to_string(kMaxInputFileBytes) +
                     " bytes (64 MiB) per input file read whole (process tables, models, screws, "
                     "profiles; run files and logs are streamed without this limit)");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open '" + path.string() + "': " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace whirl
