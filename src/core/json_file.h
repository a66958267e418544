#pragma once
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

namespace whirl {

/// Parses a JSON file; a syntax error, a truncation or a number beyond the double range is an
/// InputError naming the file (and byte). Size limit: kMaxInputFileBytes (core/atomic_file.h).
nlohmann::json ReadJsonFile(const std::filesystem::path& path);

/// Writes pretty-printed JSON (2-space indent, trailing newline) atomically.
void WriteJsonFile(const std::filesystem::path& path, const nlohmann::json& j);

/// The text WriteJsonFile writes, for a file that is written together with others.
std::string JsonFileText(const nlohmann::json& j);

/// Checks that `j` is an object whose keys are all in `allowed`; an unknown key is an InputError
/// naming `what` (e.g. "screw file 'a.json'") and the key. Catches typos in hand-written files.
void RejectUnknownKeys(const nlohmann::json& j, std::initializer_list<const char*> allowed,
                       const std::string& what);

/// Required finite number at key; an InputError names `what`, the key and the rule otherwise.
double RequireNumber(const nlohmann::json& j, const char* key, const std::string& what);

}  // namespace whirl
