#include "interp/machine_profile.h"

#include <cmath>

#include "core/error.h"
#include "core/json_file.h"

namespace whirl::interp {
namespace {

int RequireInt(const nlohmann::json& j, const char* key, const std::string& what) {
  const double v = RequireNumber(j, key, what);
  if (v != std::floor(v) || std::abs(v) > 1e6)
    throw InputError(what + ": '" + key + "' = " + j.at(key).dump() + ": must be an integer");
  return static_cast<int>(v);
}

std::string RequireString(const nlohmann::json& j, const char* key, const std::string& what) {
  if (!j.contains(key)) throw InputError(what + ": missing required key '" + key + "'");
  if (!j.at(key).is_string())
    throw InputError(what + ": '" + key + "' must be a string, got " + j.at(key).dump());
  return j.at(key).get<std::string>();
}

}  // namespace

void MachineProfile::ApplyTo(PlanOptions& o) const {
  o.axis = axis;
  o.direction = direction;
  o.machine_offset_mm = machine_offset_mm;
  if (start_position_mm) o.start_position_mm = *start_position_mm;
  o.control_dk = control_dk;
  o.md32760 = md32760;
  o.sync_id_first = sync_id_first;
  o.sync_id_last = sync_id_last;
  o.save_r_first = save_r_first;
  o.sign = ExpectedSign(direction, control_dk);
}

MachineProfile LoadMachineProfile(const std::filesystem::path& path) {
  const nlohmann::json j = ReadJsonFile(path);
  const std::string what = "machine profile '" + path.string() + "'";
  if (!j.is_object()) throw InputError(what + ": must be a JSON object");
  RejectUnknownKeys(j,
                    {"schema", "schema_version", "name", "axis", "direction", "machine_offset_mm",
                     "start_position_mm", "control_dk", "md32760", "sync_id_first", "sync_id_last",
                     "save_r_first"},
                    what);
  if (RequireString(j, "schema", what) != MachineProfile::kSchema)
    throw InputError(what + ": 'schema' must be \"" + std::string(MachineProfile::kSchema) + "\"");
  if (RequireInt(j, "schema_version", what) != MachineProfile::kSchemaVersion)
    throw InputError(what + ": 'schema_version' must be 1");
  MachineProfile m;
  m.name = RequireString(j, "name", what);
  m.axis = RequireString(j, "axis", what);
  m.direction = RequireInt(j, "direction", what);
  m.machine_offset_mm = RequireNumber(j, "machine_offset_mm", what);
  if (j.contains("start_position_mm"))
    m.start_position_mm = RequireNumber(j, "start_position_mm", what);
  m.control_dk = ParseControlDk(RequireString(j, "control_dk", what));
  m.md32760 = RequireNumber(j, "md32760", what);
  m.sync_id_first = RequireInt(j, "sync_id_first", what);
  m.sync_id_last = RequireInt(j, "sync_id_last", what);
  m.save_r_first = RequireInt(j, "save_r_first", what);
  PlanOptions check;
  m.ApplyTo(check);
  try {
    check.Validate();
  } catch (const InputError& e) {
    throw InputError(what + ": " + e.what());
  }
  return m;
}

}  // namespace whirl::interp
