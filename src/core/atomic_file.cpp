#include "core/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <random>
#include <sstream>

#include "core/error.h"

namespace whirl {

void WriteFileAtomic(const std::filesystem::path& path, const std::string& contents) {
  namespace fs = std::filesystem;
  const fs::path dir = path.has_parent_path() ? path.parent_path() : fs::path(".");
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw InputError("cannot write '" + path.string() + "': directory '" + dir.string() +
                     "' does not exist");
  }
  std::random_device rd;
  const fs::path tmp =
      dir / ("." + path.filename().string() + ".tmp" + std::to_string(::getpid()) + "_" +
             std::to_string(rd()));
  FILE* f = std::fopen(tmp.c_str(), "wb");
  if (f == nullptr) {
    throw InputError("cannot write '" + path.string() + "': " + std::strerror(errno));
  }
  const bool written = std::fwrite(contents.data(), 1, contents.size(), f) == contents.size();
  const bool flushed = std::fflush(f) == 0 && ::fsync(fileno(f)) == 0;
  const bool closed = std::fclose(f) == 0;
  if (!written || !flushed || !closed) {
    const std::string reason = std::strerror(errno);
    fs::remove(tmp, ec);
    throw InputError("cannot write '" + path.string() + "': " + reason);
  }
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError("cannot write '" + path.string() + "': rename failed: " + ec.message());
  }
}

std::string ReadTextFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open '" + path.string() + "': " + std::strerror(errno));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace whirl
