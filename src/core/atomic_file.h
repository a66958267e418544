#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace whirl {

/// Largest input file whirl reads [bytes]: 64 MiB, far above any process table, model or screw
/// file (the shipped 500-row table is about 60 kB), so a wrong path cannot exhaust memory.
inline constexpr std::uintmax_t kMaxInputFileBytes = 64ull << 20;

/// Writes `contents` to `path` atomically: into a temporary file in the same directory, flushed,
/// then renamed over `path`. A failure (disk full, missing directory, interrupted run) leaves any
/// previous file untouched and no half-written file behind. The target must be absent or a
/// regular file: a symbolic link, directory, FIFO, socket or device node at `path` is refused
/// (InputError naming the path and what it is) and left untouched. Throws InputError naming the
/// path on any failure.
void WriteFileAtomic(const std::filesystem::path& path, const std::string& contents);

/// Writes several files all-or-nothing: every target is checked (as WriteFileAtomic, and no path
/// twice), every file is written to a temporary beside its target, and only then are they renamed
/// over the targets. A failure in any step removes every temporary; a rename failing after others
/// succeeded puts the previous files back (from hard-linked backups). Throws InputError.
void WriteFilesAtomic(const std::vector<std::pair<std::filesystem::path, std::string>>& files);

/// Reads a whole text file; throws InputError naming the path if it cannot be opened, is not a
/// regular file (a FIFO, device or directory) or is larger than kMaxInputFileBytes.
std::string ReadTextFile(const std::filesystem::path& path);

}  // namespace whirl
