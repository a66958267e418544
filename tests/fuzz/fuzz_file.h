#pragma once
// The fuzz input as a file: the loaders take paths, so each input is written to one scratch file
// per process (overwritten every run) and the loader reads it like a user's file.
#include <unistd.h>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.h"

namespace whirl::fuzz {

/// True while the current input itself holds nlohmann's tag (a message quoting the input, such as
/// a parse error's "last read: ...", then holds it too, and Refused cannot tell).
inline bool& InputHoldsLibraryTag() {
  static bool holds = false;
  return holds;
}

inline std::filesystem::path FuzzFile(const std::uint8_t* data, std::size_t size,
                                      const std::string& extension) {
  InputHoldsLibraryTag() = std::string(reinterpret_cast<const char*>(data), size).find(
                               "json.exception") != std::string::npos;
  static const std::filesystem::path path =
      std::filesystem::temp_directory_path() /
      ("whirl_fuzz_" + std::to_string(::getpid()) + extension);
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

/// A refusal must state its rule: an empty message or a library's own message passed through
/// (nlohmann's "[json.exception.type_error.302] type must be string, but is number", which names
/// neither the key nor the rule) is a finding (abort), like a crash.
inline void Refused(const whirl::InputError& e) {
  const std::string m = e.what();
  if (m.empty() || (m.find("[json.exception") != std::string::npos && !InputHoldsLibraryTag())) {
    std::fprintf(stderr, "refused without naming the rule: '%s'\n", m.c_str());
    std::abort();
  }
}

/// A loaded file must never produce nonsense: a result that is not a finite number is a finding
/// (abort, so libFuzzer keeps the input), like a crash.
inline void RequireFinite(double x) {
  if (!std::isfinite(x)) std::abort();
}

}  // namespace whirl::fuzz
