#include "core/json_file.h"

#include <cmath>
#include <set>

#include "core/atomic_file.h"
#include "core/error.h"

namespace whirl {

nlohmann::json ReadJsonFile(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    throw InputError("'" + path.string() + "' is not valid JSON (byte " + std::to_string(e.byte) +
                     "): " + e.what());
  } catch (const nlohmann::json::exception& e) {  // e.g. out_of_range: a number beyond double
    throw InputError("'" + path.string() + "': " + e.what() +
                     " (rule: numbers must lie within the double range, |x| < 1.8e308)");
  }
}

std::string JsonFileText(const nlohmann::json& j) { return j.dump(2) + "\n"; }

void WriteJsonFile(const std::filesystem::path& path, const nlohmann::json& j) {
  WriteFileAtomic(path, JsonFileText(j));
}

void RejectUnknownKeys(const nlohmann::json& j, std::initializer_list<const char*> allowed,
                       const std::string& what) {
  if (!j.is_object()) throw InputError(what + ": expected a JSON object");
  std::set<std::string> ok;
  for (const char* a : allowed) ok.insert(a);
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (!ok.count(it.key())) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      throw InputError(what + ": unknown key '" + it.key() + "' (allowed: " + list + ")");
    }
  }
}

double RequireNumber(const nlohmann::json& j, const char* key, const std::string& what) {
  if (!j.contains(key)) throw InputError(what + ": missing required key '" + key + "'");
  const auto& v = j.at(key);
  if (!v.is_number()) throw InputError(what + ": '" + key + "' must be a number, got " + v.dump());
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw InputError(what + ": '" + key + "' must be finite");
  return x;
}

}  // namespace whirl
