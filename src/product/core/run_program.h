#pragma once
// Running an external program (gnuplot) without a shell: an argument vector goes straight to
// execvp, so no file name, path or user string is ever parsed by /bin/sh.
#include <filesystem>
#include <string>
#include <vector>

namespace whirl {

/// Runs `argv[0]` (looked up on PATH when it has no '/') with the arguments `argv[1..]`, in the
/// working directory `cwd` (empty: the current one), with stdin from /dev/null and stdout plus
/// stderr appended to `log_path` (empty: discarded; a relative path is relative to the caller's
/// working directory, not to `cwd`). Waits for it. Returns its exit status, or
/// 128 + signal if it was killed, or 127 if it could not be started (not found, cwd missing).
/// Never throws for a failing program; throws std::invalid_argument for an empty argv.
int RunProgram(const std::vector<std::string>& argv, const std::filesystem::path& cwd = {},
               const std::filesystem::path& log_path = {});

/// True when `RunProgram({program, args...})` exits 0 (e.g. {"gnuplot", "--version"}).
bool ProgramSucceeds(const std::vector<std::string>& argv);

}  // namespace whirl
