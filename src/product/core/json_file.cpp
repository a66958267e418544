#include "core/json_file.h"

#include <cmath>
#include <set>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/numbers.h"

namespace whirl {
namespace {

const nlohmann::json& At(const nlohmann::json& j, const char* key, const std::string& what) {
  return RequireKey(j, key, what);
}

// A number that is whole and within [min, max] (false for NaN and for anything not a number).
bool IsWholeIn(const nlohmann::json& v, double min, double max) {
  if (!v.is_number()) return false;
  const double x = v.get<double>();
  return x >= min && x <= max && x == std::floor(x);
}

// nlohmann's message without its "[json.exception.parse_error.101] " tag.
std::string Untagged(const std::string& message) {
  const auto end = message.rfind("] ", message.find(' '));
  return message.rfind("[json.exception.", 0) == 0 && end != std::string::npos
             ? message.substr(end + 2)
             : message;
}

// A value as the messages show it: compact JSON, cut after 60 characters (a message about a
// megabyte array must not repeat it).
std::string Shown(const nlohmann::json& v) {
  const std::string text = DumpJson(v, -1);
  return text.size() > 60 ? text.substr(0, 57) + "..." : text;
}

// Watches nlohmann's parse (its callback) for the first key given twice in one object: JSON
// allows it and nlohmann keeps the last value, so a file could say two things at once.
class DuplicateKeys {
 public:
  bool Event(nlohmann::json::parse_event_t event, const nlohmann::json& parsed) {
    using E = nlohmann::json::parse_event_t;
    if (event == E::object_start || event == E::array_start) {
      Element();
      levels_.push_back({event == E::object_start, {}, {}, -1});
    } else if (event == E::object_end || event == E::array_end) {
      if (!levels_.empty()) levels_.pop_back();
    } else if (event == E::key && !levels_.empty()) {
      Level& top = levels_.back();
      top.key = parsed.is_string() ? parsed.get<std::string>() : std::string();
      if (!top.keys.insert(top.key).second && first_.empty()) first_ = Path();
    } else if (event == E::value) {
      Element();
    }
    return true;  // keep everything: the file is refused afterwards if first_ is set
  }
  /// The path of the first duplicate ("drift.analog_inputs.t3_C", "runs[2].name"); empty if none.
  const std::string& first() const { return first_; }

 private:
  struct Level {
    bool object = false;
    std::set<std::string> keys;
    std::string key;
    long index = -1;
  };
  void Element() {
    if (!levels_.empty() && !levels_.back().object) ++levels_.back().index;
  }
  std::string Path() const {
    std::string path;
    for (const Level& l : levels_)
      path += l.object ? (path.empty() ? "" : ".") + l.key : "[" + std::to_string(l.index) + "]";
    return path;
  }
  std::vector<Level> levels_;
  std::string first_;
};

std::string List(std::initializer_list<const char*> items) {
  std::string list;
  for (const char* a : items) list += std::string(list.empty() ? "" : ", ") + a;
  return list;
}

}  // namespace

nlohmann::json ReadJsonFile(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  DuplicateKeys duplicates;
  nlohmann::json j;
  try {
    // Skips a UTF-8 byte-order mark, rejects invalid UTF-8.
    j = nlohmann::json::parse(text, [&duplicates](int, nlohmann::json::parse_event_t event,
                                                  nlohmann::json& parsed) {
      return duplicates.Event(event, parsed);
    });
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError("'" + path.string() + "' is not valid JSON (byte " + std::to_string(e.byte) +
                     "): " + Untagged(e.what()));
  } catch (const nlohmann::json::exception& e) {  // e.g. out_of_range: a number beyond double
    throw InputError("'" + path.string() + "': " + Untagged(e.what()) +
                     " (rule: numbers must lie within the double range, |x| < 1.8e308)");
  }
  if (!duplicates.first().empty())
    throw InputError("'" + path.string() + "': key '" + duplicates.first() +
                     "' is given twice in one object (rule: each key once; JSON readers differ "
                     "in which value counts, so whirl refuses the file: keep one)");
  return j;
}

std::string LibraryRule(const nlohmann::json::exception& e) { return Untagged(e.what()); }

std::string DumpJson(const nlohmann::json& j, int indent) {
  return j.dump(indent, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string JsonFileText(const nlohmann::json& j) { return DumpJson(j) + "\n"; }

void WriteJsonFile(const std::filesystem::path& path, const nlohmann::json& j) {
  WriteFileAtomic(path, JsonFileText(j));
}

void RejectUnknownKeys(const nlohmann::json& j, std::initializer_list<const char*> allowed,
                       const std::string& what) {
  if (!j.is_object()) throw InputError(what + ": expected a JSON object");
  std::set<std::string> ok;
  for (const char* a : allowed) ok.insert(a);
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!ok.count(it.key()))
      throw InputError(what + ": unknown key '" + it.key() + "' (allowed: " + List(allowed) + ")");
  }
}

const nlohmann::json& RequireKey(const nlohmann::json& j, const std::string& key,
                                 const std::string& what) {
  if (!j.is_object()) throw InputError(what + ": expected a JSON object");
  if (!j.contains(key)) throw InputError(what + ": missing required key '" + key + "'");
  return j.at(key);
}

double RequireFiniteValue(const nlohmann::json& v, const std::string& where) {
  if (!v.is_number()) throw InputError(where + " must be a number, got " + Shown(v));
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw InputError(where + " must be finite, got " + Shown(v));
  return x;
}

long long RequireWholeValue(const nlohmann::json& v, const std::string& where, double min,
                            double max) {
  RequireFiniteValue(v, where);
  if (!IsWholeIn(v, min, max))
    throw InputError(where + " must be a whole number in [" + FormatNumber(min) + ", " +
                     FormatNumber(max) + "], got " + Shown(v));
  return static_cast<long long>(v.get<double>());
}

std::vector<double> RequireNumbers(const nlohmann::json& v, const std::string& where) {
  if (!v.is_array())
    throw InputError(where + " must be an array of numbers, got " + Shown(v));
  std::vector<double> out;
  out.reserve(v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
    out.push_back(RequireFiniteValue(v[i], where + "[" + std::to_string(i) + "]"));
  return out;
}

double RequireNumber(const nlohmann::json& j, const char* key, const std::string& what) {
  return RequireFiniteValue(At(j, key, what), what + ": '" + key + "'");
}

double RequireNumberIn(const nlohmann::json& j, const char* key, const Range& range,
                       const std::string& what) {
  const double x = RequireNumber(j, key, what);
  CheckRange(x, range, key, what);
  return x;
}

void OptionalNumberIn(const nlohmann::json& j, const char* key, const Range& range, double& value,
                      const std::string& what) {
  if (j.is_object() && j.contains(key)) value = RequireNumberIn(j, key, range, what);
}

long long RequireInteger(const nlohmann::json& j, const char* key, long long min, long long max,
                         const std::string& what) {
  const auto& v = At(j, key, what);
  const std::string rule =
      "must be a whole number in " + std::to_string(min) + ".." + std::to_string(max);
  if (!IsWholeIn(v, static_cast<double>(min), static_cast<double>(max)))
    throw InputError(what + ": '" + key + "' = " + Shown(v) + " breaks the rule: " + rule);
  return static_cast<long long>(v.get<double>());
}

std::string RequireString(const nlohmann::json& j, const char* key, const std::string& what,
                          std::size_t max_length) {
  const auto& v = At(j, key, what);
  if (!v.is_string())
    throw InputError(what + ": '" + key + "' must be a string, got " + Shown(v));
  std::string s = v.get<std::string>();
  if (s.size() > max_length)
    throw InputError(what + ": '" + key + "' has " + std::to_string(s.size()) +
                     " bytes; the limit is " + std::to_string(max_length));
  return s;
}

const nlohmann::json& RequireObject(const nlohmann::json& j, const char* key,
                                    const std::string& what) {
  const auto& v = At(j, key, what);
  if (!v.is_object())
    throw InputError(what + ": '" + key + "' must be a JSON object, got " + Shown(v));
  return v;
}

const nlohmann::json& RequireArray(const nlohmann::json& j, const char* key, const std::string& what,
                                   std::size_t max_count) {
  const auto& v = At(j, key, what);
  if (!v.is_array()) throw InputError(what + ": '" + key + "' must be an array, got " + Shown(v));
  if (v.size() > max_count)
    throw InputError(what + ": '" + key + "' has " + std::to_string(v.size()) +
                     " elements; the limit is " + std::to_string(max_count));
  return v;
}

std::vector<std::string> RequireStrings(const nlohmann::json& j, const char* key,
                                        const std::string& what, std::size_t max_count,
                                        std::size_t max_length) {
  const auto& a = RequireArray(j, key, what, max_count);
  std::vector<std::string> out;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const std::string where = what + ": '" + key + "'[" + std::to_string(i) + "]";
    if (!a[i].is_string()) throw InputError(where + " must be a string, got " + Shown(a[i]));
    if (a[i].get_ref<const std::string&>().size() > max_length)
      throw InputError(where + " has " + std::to_string(a[i].get_ref<const std::string&>().size()) +
                       " bytes; the limit is " + std::to_string(max_length));
    out.push_back(a[i].get<std::string>());
  }
  return out;
}

std::vector<double> RequireNumberArray(const nlohmann::json& j, const char* key,
                                       const std::string& what, std::size_t max_count) {
  RequireArray(j, key, what, max_count);
  return RequireNumbers(j.at(key), what + ": '" + key + "'");
}

std::vector<long long> RequireIntegers(const nlohmann::json& j, const char* key, long long min,
                                       long long max, const std::string& what,
                                       std::size_t max_count) {
  const auto& a = RequireArray(j, key, what, max_count);
  std::vector<long long> out;
  for (std::size_t i = 0; i < a.size(); ++i)
    out.push_back(RequireWholeValue(a[i], what + ": '" + key + "'[" + std::to_string(i) + "]",
                                    static_cast<double>(min), static_cast<double>(max)));
  return out;
}

std::string RequireOneOf(const nlohmann::json& j, const char* key,
                         std::initializer_list<const char*> allowed, const std::string& what) {
  const std::string s = RequireString(j, key, what);
  for (const char* a : allowed)
    if (s == a) return s;
  throw InputError(what + ": '" + key + "' = " + Shown(s) + " must be one of " +
                   List(allowed));
}

void RequireSchema(const nlohmann::json& j, const std::string& schema, int version,
                   const std::string& what, const char* schema_key) {
  if (!j.is_object()) throw InputError(what + ": expected a JSON object");
  if (!j.contains(schema_key) || !j.at(schema_key).is_string() ||
      j.at(schema_key).get<std::string>() != schema)
    throw InputError(what + ": '" + schema_key + "' must be \"" + schema + "\"" +
                     (j.contains(schema_key) ? ", got " + Shown(j.at(schema_key))
                                             : std::string(" (missing)")));
  const bool have = j.contains("schema_version");
  const auto& v = have ? j.at("schema_version") : j;
  if (!have || !v.is_number() || v.get<double>() != version)
    throw InputError(what + ": 'schema_version' = " + (have ? Shown(v) : "(missing)") +
                     " breaks the rule: this whirl reads schema_version " +
                     std::to_string(version));
}

}  // namespace whirl
