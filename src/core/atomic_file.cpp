#include "core/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include "core/error.h"

namespace whirl {
namespace {
namespace fs = std::filesystem;

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

// The rule of the writer: the target is absent or a regular file, in an existing directory.
void CheckTarget(const fs::path& path) {
  if (path.empty() || !path.has_filename())
    throw InputError("cannot write " + Quoted(path) + ": not a file path");
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
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

fs::path TemporaryName(const fs::path& path, const char* what) {
  static thread_local std::mt19937_64 rng{std::random_device{}()};
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  return dir / ("." + path.filename().string() + what + std::to_string(::getpid()) + "_" +
                std::to_string(rng()));
}

// Writes `contents` to a new temporary file beside `path`, flushed to disk; returns its name.
fs::path WriteTemporary(const fs::path& path, const std::string& contents) {
  const fs::path tmp = TemporaryName(path, ".tmp");
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

void WriteFilesAtomic(const std::vector<std::pair<fs::path, std::string>>& files) {
  std::set<fs::path> seen;
  for (const auto& [path, text] : files) {
    CheckTarget(path);
    if (!seen.insert(fs::weakly_canonical(path)).second)
      throw InputError("cannot write " + Quoted(path) + ": the same file is given twice");
  }
  // 1. Every file into a temporary beside its target: a failure here leaves nothing behind.
  std::vector<fs::path> tmps;
  try {
    for (const auto& [path, text] : files) tmps.push_back(WriteTemporary(path, text));
  } catch (...) {
    RemoveAll(tmps);
    throw;
  }
  // 2. Rename them over the targets; an existing target is hard-linked to a backup first, so a
  // failing rename restores every target already replaced.
  std::vector<fs::path> backups(files.size());
  std::vector<bool> existed(files.size(), false);
  for (std::size_t i = 0; i < files.size(); ++i) {
    const fs::path& path = files[i].first;
    std::error_code ec;
    existed[i] = fs::is_regular_file(fs::symlink_status(path, ec));
    if (existed[i]) {
      backups[i] = TemporaryName(path, ".bak");
      fs::create_hard_link(path, backups[i], ec);
      if (ec) backups[i].clear();  // e.g. a file system without hard links: no restore possible
    }
    fs::rename(tmps[i], path, ec);
    if (!ec) continue;
    const std::string reason = ec.message();
    for (std::size_t k = 0; k < i; ++k) {
      if (!backups[k].empty())
        fs::rename(backups[k], files[k].first, ec);
      else if (!existed[k])
        fs::remove(files[k].first, ec);
    }
    RemoveAll(tmps);
    RemoveAll(backups);
    throw InputError("cannot write " + Quoted(path) + ": rename failed: " + reason +
                     (i > 0 ? " (the files written before it were restored)" : ""));
  }
  RemoveAll(backups);
}

std::string ReadTextFile(const fs::path& path) {
  // Only regular files: a FIFO or a device would block or never end, a directory has no text.
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    throw InputError("cannot open " + Quoted(path) + ": " + std::strerror(errno));
  if (!S_ISREG(st.st_mode))
    throw InputError("cannot read " + Quoted(path) + ": it is " + KindOf(st.st_mode) +
                     "; whirl reads only regular files");
  if (static_cast<std::uintmax_t>(st.st_size) > kMaxInputFileBytes)
    throw InputError("cannot read " + Quoted(path) + ": " + std::to_string(st.st_size) +
                     " bytes breaks the limit of " + std::to_string(kMaxInputFileBytes) +
                     " bytes (64 MiB) per input file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open '" + path.string() + "': " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace whirl
