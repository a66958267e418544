#include "interp/machine_profile.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"
#include "core/json_file.h"

namespace whirl::interp {
namespace {

// The smallest ranges any program needs, so that a profile one command accepts serves every
// command: the plan one action for its single segment and one for the restore; the drift action
// for a one-sensor model one action for the rise and, with reference "start", one to capture the
// start temperatures and one to set the flag, then one for SD43900; with the slope object the
// slope model's three again plus one for S_m. $AC_PARAM: the liveness slot, the model's
// feature, reference and flag, and with the slope object the slope model's three and S_m.
constexpr int kMinPlanIds = 2;
// Upper bounds of the control section (machine data counts far beyond any 840D: typing errors).
constexpr long long kMaxSyncElements = 1000000;
constexpr long long kMaxAcParams = 10000;
int MinDriftIds(const DriftActionOptions& d) { return d.has_slope ? 8 : 4; }
int MinDriftSlots(const DriftActionOptions& d) { return d.has_slope ? 8 : 4; }

// A whole number within +-1e6 (the fields' own ranges are checked where they are used).
int RequireInt(const nlohmann::json& j, const char* key, const std::string& what) {
  return static_cast<int>(RequireInteger(j, key, -1000000, 1000000, what));
}

ControlLimits ReadControlSection(const nlohmann::json& j, const std::string& what) {
  const std::string w = what + ", object 'control'";
  if (!j.is_object()) throw InputError(w + ": must be a JSON object");
  RejectUnknownKeys(j, {"md10300_analog_inputs", "md28250_sync_elements", "md28254_ac_params"}, w);
  // Each value within its machine datum's range where it is read: no value may stand for "not
  // stated" (-1 once switched every check of the control's limits off).
  const auto datum = [&](const char* key, long long lo, long long hi, const char* name) {
    try {
      return static_cast<int>(RequireInteger(j, key, lo, hi, w));
    } catch (const InputError& e) {
      throw InputError(std::string(e.what()) + " (" + name + " of the control)");
    }
  };
  ControlLimits c;
  c.analog_inputs =
      datum("md10300_analog_inputs", 0, kMaxAnalogIndex, "MD10300 $MN_FASTIO_ANA_NUM_INPUTS");
  c.sync_elements =
      datum("md28250_sync_elements", 1, kMaxSyncElements, "MD28250 $MC_MM_NUM_SYNC_ELEMENTS");
  c.ac_params = datum("md28254_ac_params", 1, kMaxAcParams, "MD28254 $MC_MM_NUM_AC_PARAM");
  return c;
}

void ReadAnalogInputs(const nlohmann::json& j, const std::string& w, DriftActionOptions& d) {
  if (!j.contains("analog_inputs") || !j.at("analog_inputs").is_object())
    throw InputError(w + ": 'analog_inputs' must be an object {column: {index, scale, offset}}");
  for (const auto& [name, a] : j.at("analog_inputs").items()) {
    const std::string wa = w + ", analog input '" + name + "'";
    if (!a.is_object()) throw InputError(wa + ": must be an object {index, scale, offset}");
    RejectUnknownKeys(a, {"index", "scale", "offset"}, wa);
    d.inputs[name] = {RequireInt(a, "index", wa), RequireNumber(a, "scale", wa),
                      RequireNumber(a, "offset", wa)};
  }
}

// Version 1 had no param_last: the slots up to the lowest workpiece slot above param_first.
int DefaultParamLast(const DriftActionOptions& d) {
  int last = 9999;
  for (int slot : {d.workpiece_k0_param, d.workpiece_slope_param,
                   d.workpiece_slope_param < 0 ? -1 : d.workpiece_slope_param + 1})
    if (slot > d.param_first) last = std::min(last, slot - 1);
  return last;
}

DriftActionOptions ReadDriftSection(const nlohmann::json& j, const std::string& what,
                                    int version) {
  const std::string w = what + ", object 'drift'";
  if (!j.is_object()) throw InputError(w + ": must be a JSON object");
  RejectUnknownKeys(
      j,
      {"sync_id_first", "sync_id_last", "param_first", "param_last", "save_r_first", "ipo_cycle_ms",
       "error_direction", "workpiece_k0_param", "workpiece_slope_param", "blank_param",
       "missing_alarm", "slope", "analog_inputs"},
      w);
  DriftActionOptions d;
  d.sync_id_first = RequireInt(j, "sync_id_first", w);
  d.sync_id_last = RequireInt(j, "sync_id_last", w);
  d.param_first = RequireInt(j, "param_first", w);
  d.save_r_first = RequireInt(j, "save_r_first", w);
  d.ipo_cycle_ms = RequireNumber(j, "ipo_cycle_ms", w);
  d.error_direction = RequireInt(j, "error_direction", w);
  // Optional slots are absent or a slot: -1 ("none", the in-memory default) is not a value a
  // file may give, and param_last bounds the action's slots (no value lifts the bound).
  if (j.contains("workpiece_k0_param"))
    d.workpiece_k0_param = static_cast<int>(RequireInteger(j, "workpiece_k0_param", 0, 9999, w));
  if (j.contains("workpiece_slope_param"))
    d.workpiece_slope_param =
        static_cast<int>(RequireInteger(j, "workpiece_slope_param", 0, 9998, w));
  if (j.contains("blank_param"))
    d.blank_param = static_cast<int>(RequireInteger(j, "blank_param", 0, 9998, w));
  if (j.contains("missing_alarm")) d.missing_alarm = RequireInt(j, "missing_alarm", w);
  if (version >= 2 || j.contains("param_last")) {
    d.param_last = static_cast<int>(RequireInteger(j, "param_last", 0, 9999, w));
  } else {
    d.param_last = DefaultParamLast(d);
    if (d.param_last < d.param_first + 3)
      throw InputError(w + ": a workpiece slot (workpiece_k0_param, workpiece_slope_param) lies "
                       "within the drift action's own $AC_PARAM slots from param_first " +
                       std::to_string(d.param_first) + " (liveness, features, references, flag)");
  }
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
  ReadAnalogInputs(j, w, d);
  return d;
}

bool Overlap(int a0, int a1, int b0, int b1) { return a0 <= b1 && b0 <= a1; }
std::string Range(int a, int b) { return std::to_string(a) + ".." + std::to_string(b); }

// The drift section against the plan's part: IDs, R parameters, alarms, $AC_PARAM slots.
void CheckDriftAgainstPlan(const MachineProfile& m) {
  const DriftActionOptions& d = *m.drift;
  if (d.sync_id_first <= m.sync_id_last)
    throw InputError("the drift action's IDs drift.sync_id_first..sync_id_last " +
                     Range(d.sync_id_first, d.sync_id_last) + " must lie above the plan's " +
                     Range(m.sync_id_first, m.sync_id_last) +
                     ": disjoint, so the plan never cancels the drift action, and higher, because "
                     "actions run in ID order and the plan's K0 must be written before the drift "
                     "action adds it in the same cycle");
  if (d.sync_id_last - d.sync_id_first + 1 < MinDriftIds(d))
    throw InputError("drift.sync_id_first..sync_id_last " + Range(d.sync_id_first, d.sync_id_last) +
                     ": the smallest drift action takes " + std::to_string(MinDriftIds(d)) +
                     " IDs (a one-sensor model" + (d.has_slope ? " and slope model" : "") +
                     ", reference start)");
  const int param_last = d.param_last < 0 ? 9999 : d.param_last;
  if (param_last - d.param_first + 1 < MinDriftSlots(d))
    throw InputError("drift.param_first..param_last " + Range(d.param_first, param_last) +
                     ": the smallest drift action takes " + std::to_string(MinDriftSlots(d)) +
                     " $AC_PARAM slots (liveness, a feature, a reference, the flag" +
                     (d.has_slope ? "; the slope model's three and S_m" : "") + ")");
  if (d.has_slope && d.workpiece_k0_param >= 0 && d.workpiece_slope_param < 0)
    throw InputError(
        "drift.slope with drift.workpiece_k0_param needs drift.workpiece_slope_param: a slope "
        "model beside a plan that writes SD43910 itself would make two writers of it");
  if (Overlap(d.save_r_first, d.save_r_first + 4, m.save_r_first, m.save_r_first + 3))
    throw InputError("the drift action's R" + std::to_string(d.save_r_first) + "..R" +
                     std::to_string(d.save_r_first + 4) + " (drift.save_r_first) overlap the plan's R" +
                     std::to_string(m.save_r_first) + "..R" + std::to_string(m.save_r_first + 3) +
                     " (save_r_first)");
  if (m.start_alarm >= d.missing_alarm && m.start_alarm <= d.missing_alarm + 3)
    throw InputError("start_alarm " + std::to_string(m.start_alarm) +
                     " is one of the drift alarms drift.missing_alarm.." +
                     Range(d.missing_alarm, d.missing_alarm + 3) +
                     ": each alarm needs its own number");
  for (const auto& [key, slot] :
       {std::pair{"drift.workpiece_k0_param", d.workpiece_k0_param},
        {"drift.workpiece_slope_param", d.workpiece_slope_param},
        {"drift.workpiece_slope_param + 1",
         d.workpiece_slope_param < 0 ? -1 : d.workpiece_slope_param + 1},
        {"drift.blank_param", d.blank_param},
        {"drift.blank_param + 1", d.blank_param < 0 ? -1 : d.blank_param + 1}})
    if (slot >= 0 && Overlap(slot, slot, d.param_first, param_last))
      throw InputError(std::string(key) + " " + std::to_string(slot) +
                       " lies in the drift action's own $AC_PARAM slots drift.param_first.." +
                       "param_last " + Range(d.param_first, param_last) +
                       ": the plan would overwrite the action's values");
}

// What the profile alone decides about the control's limits (MD28250; MD10300 and MD28254 are
// checked with the drift options, which carry them).
void CheckControlLimits(const MachineProfile& m) {
  const ControlLimits& c = m.control;
  c.Validate();
  if (!c.Stated()) return;
  int actions = m.sync_id_last - m.sync_id_first + 1;
  if (m.drift) actions += m.drift->sync_id_last - m.drift->sync_id_first + 1;
  if (actions > c.sync_elements)
    throw InputError("whirl's ID ranges hold " + std::to_string(actions) +
                     " synchronized actions, but MD28250 $MC_MM_NUM_SYNC_ELEMENTS is " +
                     std::to_string(c.sync_elements) +
                     " (control.md28250_sync_elements) and every action takes at least one element");
}

}  // namespace

void MachineProfile::Validate() const {
  const std::string what = "machine profile '" + source + "'";
  try {
    if (!(sync_id_first >= 1 && sync_id_last - sync_id_first + 1 >= kMinPlanIds))
      throw InputError("sync_id_first..sync_id_last " + Range(sync_id_first, sync_id_last) +
                       ": whirl's IDs within 1..255, at least " + std::to_string(kMinPlanIds) +
                       " (a plan's first segment and its restore)");
    if (save_r_first < 0)
      throw InputError("save_r_first " + std::to_string(save_r_first) +
                       ": required, within 0..9996 (the R parameters reserved for whirl)");
    PlanOptions check;
    Fill(check);
    check.Validate();
    CheckControlLimits(*this);
    if (drift) {
      FillDrift().Validate();
      CheckDriftAgainstPlan(*this);
    }
  } catch (const InputError& e) {
    throw InputError(what + ": " + e.what());
  }
}

void MachineProfile::ApplyCombinedTo(PlanOptions& o) const {
  if (!drift || drift->workpiece_k0_param < 0)
    throw InputError("machine profile '" + source +
                     "': combining the plan with the drift action "
                     "needs a 'drift' object with 'workpiece_k0_param'");
  ApplyTo(o);
  o.workpiece_k0_param = drift->workpiece_k0_param;
  o.workpiece_slope_param = drift->workpiece_slope_param;
  o.blank_param = drift->blank_param;
}

DriftActionOptions MachineProfile::DriftOptions() const {
  if (!drift)
    throw InputError("machine profile '" + source +
                     "': no 'drift' object (IDs, $AC_PARAM "
                     "slots, R parameters, interpolation cycle, analog inputs)");
  Validate();
  return FillDrift();
}

DriftActionOptions MachineProfile::FillDrift() const {
  DriftActionOptions d = *drift;
  d.axis = axis;
  d.control_dk = control_dk;
  d.control = control;
  d.plan_marker_r = save_r_first + 3;  // a plan's compensation left active: the preamble alarms
  return d;
}

void MachineProfile::ApplyTo(PlanOptions& o) const {
  Validate();
  Fill(o);
}

void MachineProfile::Fill(PlanOptions& o) const {
  o.axis = axis;
  o.direction = direction;
  o.machine_offset_mm = machine_offset_mm;
  if (start_position_mm) o.start_position_mm = *start_position_mm;
  o.control_dk = control_dk;
  o.md32760 = md32760;
  o.sync_id_first = sync_id_first;
  o.sync_id_last = sync_id_last;
  o.save_r_first = save_r_first;
  o.start_alarm = start_alarm;
  o.sign = ExpectedSign(direction, control_dk);
  // A machine with a drift action: every plan checks it (a plan that writes the setting data
  // itself must not run beside it).
  o.drift_alive_param = drift ? drift->param_first : -1;
  if (drift) o.drift_missing_alarm = drift->missing_alarm;
}

bool MachineProfile::Illustrative() const {
  return name.find("illustrative values") != std::string::npos;
}

MachineProfile LoadMachineProfile(const std::filesystem::path& path) {
  const nlohmann::json j = ReadJsonFile(path);
  const std::string what = "machine profile '" + path.string() + "'";
  if (!j.is_object()) throw InputError(what + ": must be a JSON object");
  RejectUnknownKeys(j,
                    {"schema", "schema_version", "name", "axis", "direction", "machine_offset_mm",
                     "start_position_mm", "control_dk", "md32760", "sync_id_first", "sync_id_last",
                     "save_r_first", "start_alarm", "control", "drift"},
                    what);
  if (RequireString(j, "schema", what) != MachineProfile::kSchema)
    throw InputError(what + ": 'schema' must be \"" + std::string(MachineProfile::kSchema) + "\"");
  MachineProfile m;
  m.schema_version = RequireInt(j, "schema_version", what);
  if (m.schema_version != 1 && m.schema_version != MachineProfile::kSchemaVersion)
    throw InputError(what + ": 'schema_version' must be 2 (or 1, read with documented defaults)");
  const bool v2 = m.schema_version >= 2;
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
  if (v2 || j.contains("control")) {
    if (!j.contains("control")) throw InputError(what + ": missing required key 'control'");
    m.control = ReadControlSection(j.at("control"), what);
  }
  if (j.contains("drift")) m.drift = ReadDriftSection(j.at("drift"), what, m.schema_version);
  if (v2 || j.contains("start_alarm"))
    m.start_alarm = RequireInt(j, "start_alarm", what);
  else  // version 1: the number after the drift alarms
    m.start_alarm = m.drift ? m.drift->missing_alarm + 4 : kDefaultStartAlarm;
  m.Validate();
  return m;
}

}  // namespace whirl::interp
