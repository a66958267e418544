#pragma once
// JSON files: reading, writing, and the field checks every loader uses, so a file field breaks a
// rule with the same message as the command-line flag of the same quantity (core/limits.h Range):
// "<what>: <key> = <value> breaks the rule: ...", `what` naming the file (e.g. "screw file
// 'a.json'"), `key` the field as the user wrote it.
#include <filesystem>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/limits.h"

namespace whirl {

/// Parses a JSON file; a syntax error, a truncation, text that is not UTF-8, a number beyond
/// the double range or a key given twice in one object (JSON allows it, readers differ in which
/// value counts) is an InputError naming the file (and the byte, or the key's path). A UTF-8 byte-order mark
/// at the start is skipped. Size limit: kMaxInputFileBytes (core/atomic_file.h).
nlohmann::json ReadJsonFile(const std::filesystem::path& path);

/// nlohmann's message of `e` without its "[json.exception.type_error.302] " tag ("type must be
/// number, but is string"), for a message that names the key itself.
std::string LibraryRule(const nlohmann::json::exception& e);

/// JSON text (`indent` spaces, as nlohmann::json::dump). A string holding bytes that are not
/// UTF-8 (a file name from the command line) gets U+FFFD in their place instead of an exception.
std::string DumpJson(const nlohmann::json& j, int indent = 2);

/// Writes pretty-printed JSON (2-space indent, trailing newline, DumpJson) atomically.
void WriteJsonFile(const std::filesystem::path& path, const nlohmann::json& j);

/// The text WriteJsonFile writes, for a file that is written together with others.
std::string JsonFileText(const nlohmann::json& j);

/// Checks that `j` is an object whose keys are all in `allowed`; an unknown key is an InputError
/// naming `what` (e.g. "screw file 'a.json'") and the key. Catches typos in hand-written files.
void RejectUnknownKeys(const nlohmann::json& j, std::initializer_list<const char*> allowed,
                       const std::string& what);

/// The value at `key` of the object `j`; InputError "<what>: expected a JSON object" or
/// "<what>: missing required key '<key>'" otherwise.
const nlohmann::json& RequireKey(const nlohmann::json& j, const std::string& key,
                                 const std::string& what);

/// `v` (an array element, or a value looked up already) as a finite number; InputError
/// "<where> must be a number, got <v>" or "<where> must be finite, got <v>" otherwise.
double RequireFiniteValue(const nlohmann::json& v, const std::string& where);

/// `v` as a whole number in [min, max], checked before any cast (a float-to-integer cast out of
/// range is undefined behaviour); InputError "<where> must be a whole number in [min, max], got
/// <v>" otherwise (1.0 is accepted as 1).
long long RequireWholeValue(const nlohmann::json& v, const std::string& where, double min,
                            double max);

/// `v` as an array of finite numbers; InputError "<where> must be an array of numbers, got <v>"
/// or "<where>[<i>] must be a number, got <x>" otherwise.
std::vector<double> RequireNumbers(const nlohmann::json& v, const std::string& where);

/// Required finite number at key; an InputError names `what`, the key and the rule otherwise.
double RequireNumber(const nlohmann::json& j, const char* key, const std::string& what);

/// Required number at key within `range` (core/limits.h); the message names `what`, the key, the
/// value and the range with its unit.
double RequireNumberIn(const nlohmann::json& j, const char* key, const Range& range,
                       const std::string& what);

/// As RequireNumberIn when the key is present; leaves `value` (the default) unchanged otherwise.
void OptionalNumberIn(const nlohmann::json& j, const char* key, const Range& range, double& value,
                      const std::string& what);

/// Required whole number at key in [min, max]: a string ("1"), a fraction (1.5) or a number out
/// of range is an InputError naming `what` and the key (1.0 is accepted as 1).
long long RequireInteger(const nlohmann::json& j, const char* key, long long min, long long max,
                         const std::string& what);

/// Required string at key of at most `max_length` bytes.
std::string RequireString(const nlohmann::json& j, const char* key, const std::string& what,
                          std::size_t max_length = 1000);

/// Required JSON object at key; InputError "<what>: '<key>' must be a JSON object, got <v>".
const nlohmann::json& RequireObject(const nlohmann::json& j, const char* key,
                                    const std::string& what);

/// Required array at key of at most `max_count` elements (any kind; the caller checks them).
const nlohmann::json& RequireArray(const nlohmann::json& j, const char* key, const std::string& what,
                                   std::size_t max_count = 1000000);

/// Required array of strings at key: at most `max_count`, each at most `max_length` bytes. The
/// message names the key and the element ("'sensors'[2] must be a string, got 5").
std::vector<std::string> RequireStrings(const nlohmann::json& j, const char* key,
                                        const std::string& what, std::size_t max_count = 100000,
                                        std::size_t max_length = 1000);

/// Required array of finite numbers at key, at most `max_count` of them.
std::vector<double> RequireNumberArray(const nlohmann::json& j, const char* key,
                                       const std::string& what, std::size_t max_count = 10000000);

/// Required array of whole numbers in [min, max] at key, at most `max_count` of them.
std::vector<long long> RequireIntegers(const nlohmann::json& j, const char* key, long long min,
                                       long long max, const std::string& what,
                                       std::size_t max_count = 1000000);

/// Required string at key that is one of `allowed`; the message lists them.
std::string RequireOneOf(const nlohmann::json& j, const char* key,
                         std::initializer_list<const char*> allowed, const std::string& what);

/// The schema of a versioned file: `j` is an object whose `schema_key` (usually "schema") is the
/// string `schema` and whose "schema_version" is the whole number `version`. InputError naming
/// `what` and the key otherwise (a missing key, 99, "1" or 1.5 for version 1).
void RequireSchema(const nlohmann::json& j, const std::string& schema, int version,
                   const std::string& what, const char* schema_key = "schema");

}  // namespace whirl
