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

DriftActionOptions ReadDriftSection(const nlohmann::json& j, const std::string& what) {
  const std::string w = what + ", object 'drift'";
  if (!j.is_object()) throw InputError(w + ": must be a JSON object");
  RejectUnknownKeys(j,
                    {"sync_id_first", "sync_id_last", "param_first", "save_r_first", "ipo_cycle_ms",
                     "error_direction", "workpiece_k0_param", "workpiece_slope_param",
                     "missing_alarm", "slope", "analog_inputs"},
                    w);
  DriftActionOptions d;
  d.sync_id_first = RequireInt(j, "sync_id_first", w);
  d.sync_id_last = RequireInt(j, "sync_id_last", w);
  d.param_first = RequireInt(j, "param_first", w);
  d.save_r_first = RequireInt(j, "save_r_first", w);
  d.ipo_cycle_ms = RequireNumber(j, "ipo_cycle_ms", w);
  d.error_direction = RequireInt(j, "error_direction", w);
  if (j.contains("workpiece_k0_param"))
    d.workpiece_k0_param = RequireInt(j, "workpiece_k0_param", w);
  if (j.contains("workpiece_slope_param"))
    d.workpiece_slope_param = RequireInt(j, "workpiece_slope_param", w);
  if (j.contains("missing_alarm")) d.missing_alarm = RequireInt(j, "missing_alarm", w);
  if (j.contains("slope")) {
    const nlohmann::json& g = j.at("slope");
    const std::string wg = w + ", object 'slope'";
    if (!g.is_object())
      throw InputError(wg + ": must be an object {fixed_end_position_mm, growth_direction}");
    RejectUnknownKeys(g, {"fixed_end_position_mm", "growth_direction"}, wg);
    d.has_slope = true;
    d.slope_fixed_end_mm = RequireNumber(g, "fixed_end_position_mm", wg);
    d.slope_growth_direction = RequireInt(g, "growth_direction", wg);
  }
  if (!j.contains("analog_inputs") || !j.at("analog_inputs").is_object())
    throw InputError(w + ": 'analog_inputs' must be an object {column: {index, scale, offset}}");
  for (const auto& [name, a] : j.at("analog_inputs").items()) {
    const std::string wa = w + ", analog input '" + name + "'";
    if (!a.is_object()) throw InputError(wa + ": must be an object {index, scale, offset}");
    RejectUnknownKeys(a, {"index", "scale", "offset"}, wa);
    d.inputs[name] = {RequireInt(a, "index", wa), RequireNumber(a, "scale", wa),
                      RequireNumber(a, "offset", wa)};
  }
  return d;
}

bool Overlap(int a0, int a1, int b0, int b1) { return a0 <= b1 && b0 <= a1; }

void CheckDisjoint(const MachineProfile& m, const std::string& what) {
  const DriftActionOptions& d = *m.drift;
  if (d.sync_id_first <= m.sync_id_last)
    throw InputError(what + ": the drift action's IDs " + std::to_string(d.sync_id_first) + ".." +
                     std::to_string(d.sync_id_last) + " must lie above the plan's " +
                     std::to_string(m.sync_id_first) + ".." + std::to_string(m.sync_id_last) +
                     ": disjoint, so the plan never cancels the drift action, and higher, because "
                     "actions run in ID order and the plan's K0 must be written before the drift "
                     "action adds it in the same cycle");
  if (Overlap(d.save_r_first, d.save_r_first + 4, m.save_r_first, m.save_r_first + 3))
    throw InputError(what + ": the drift action's R" + std::to_string(d.save_r_first) + "..R" +
                     std::to_string(d.save_r_first + 4) + " overlap the plan's R" +
                     std::to_string(m.save_r_first) + "..R" + std::to_string(m.save_r_first + 3));
}

}  // namespace

void MachineProfile::ApplyCombinedTo(PlanOptions& o) const {
  if (!drift || drift->workpiece_k0_param < 0)
    throw InputError("machine profile '" + source +
                     "': combining the plan with the drift action "
                     "needs a 'drift' object with 'workpiece_k0_param'");
  ApplyTo(o);
  o.workpiece_k0_param = drift->workpiece_k0_param;
  o.workpiece_slope_param = drift->workpiece_slope_param;
}

DriftActionOptions MachineProfile::DriftOptions() const {
  if (!drift)
    throw InputError("machine profile '" + source +
                     "': no 'drift' object (IDs, $AC_PARAM "
                     "slots, R parameters, interpolation cycle, analog inputs)");
  DriftActionOptions d = *drift;
  d.axis = axis;
  d.control_dk = control_dk;
  d.plan_marker_r = save_r_first + 3;  // a plan's compensation left active: the preamble alarms
  return d;
}

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
  // A machine with a drift action: every plan checks it (a plan that writes the setting data
  // itself must not run beside it).
  o.drift_alive_param = drift ? drift->param_first : -1;
  if (drift) o.drift_missing_alarm = drift->missing_alarm;
}

MachineProfile LoadMachineProfile(const std::filesystem::path& path) {
  const nlohmann::json j = ReadJsonFile(path);
  const std::string what = "machine profile '" + path.string() + "'";
  if (!j.is_object()) throw InputError(what + ": must be a JSON object");
  RejectUnknownKeys(j,
                    {"schema", "schema_version", "name", "axis", "direction", "machine_offset_mm",
                     "start_position_mm", "control_dk", "md32760", "sync_id_first", "sync_id_last",
                     "save_r_first", "drift"},
                    what);
  if (RequireString(j, "schema", what) != MachineProfile::kSchema)
    throw InputError(what + ": 'schema' must be \"" + std::string(MachineProfile::kSchema) + "\"");
  if (RequireInt(j, "schema_version", what) != MachineProfile::kSchemaVersion)
    throw InputError(what + ": 'schema_version' must be 1");
  MachineProfile m;
  m.name = RequireString(j, "name", what);
  m.axis = RequireString(j, "axis", what);
  m.direction = RequireInt(j, "direction", what);
  m.machine_offset_mm = RequireNumberIn(j, "machine_offset_mm", kAxisPositionRange, what);
  if (j.contains("start_position_mm"))
    m.start_position_mm = RequireNumberIn(j, "start_position_mm", kAxisPositionRange, what);
  m.control_dk = ParseControlDk(RequireString(j, "control_dk", what));
  m.md32760 = RequireNumber(j, "md32760", what);
  m.sync_id_first = RequireInt(j, "sync_id_first", what);
  m.sync_id_last = RequireInt(j, "sync_id_last", what);
  m.save_r_first = RequireInt(j, "save_r_first", what);
  m.source = path.string();
  if (j.contains("drift")) {
    m.drift = ReadDriftSection(j.at("drift"), what);
    try {
      m.DriftOptions().Validate();
    } catch (const InputError& e) {
      throw InputError(what + ": " + e.what());
    }
    CheckDisjoint(m, what);
  }
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
