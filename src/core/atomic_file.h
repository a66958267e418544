#pragma once
#include <filesystem>
#include <string>

namespace whirl {

/// Writes `contents` to `path` atomically: into a temporary file in the same directory, flushed,
/// then renamed over `path`. A failure (disk full, missing directory, interrupted run) leaves any
/// previous file untouched and no half-written file behind. Throws InputError naming the path.
void WriteFileAtomic(const std::filesystem::path& path, const std::string& contents);

/// Reads a whole text file; throws InputError naming the path if it cannot be opened.
std::string ReadTextFile(const std::filesystem::path& path);

}  // namespace whirl
