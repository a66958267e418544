#include "interp/sinumerik.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"
#include "core/safe_text.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/numbers.h"

namespace whirl::interp {
namespace {

constexpr const char* kPlanSchema = "whirl.plan";
constexpr int kPlanSchemaVersion = 2;
constexpr int kMaxSyncActionId = 255;

void CheckFinitePositive(double v, const std::string& field) {
  if (!std::isfinite(v) || !(v > 0))
    throw InputError(field + " = " + FormatSignificant(v, 10) +
                     ": must be a positive finite number");
}

CompensationSegment MakeSegment(const PlanOptions& o, double feed, double t_a, double t_b,
                                double l_a, double l_b) {
  CompensationSegment s;
  const double sign = SignFactor(o.sign);
  s.t_a_s = t_a;
  s.t_b_s = t_b;
  s.p_a_mm = AxisPositionMm(o, feed, t_a);
  s.p_b_mm = AxisPositionMm(o, feed, t_b);
  s.l_a_um = l_a;
  s.l_b_um = l_b;
  // The values the writers print (RoundTo); the chord's slope uses the unrounded positions.
  s.sd43900_mm = RoundTo(sign * l_a / 1000.0, kDecimalsSd43900Mm);
  s.sd43910 = RoundTo(sign * (l_b - l_a) / 1000.0 / (s.p_b_mm - s.p_a_mm), kDecimalsSd43910);
  s.p_a_mm = RoundTo(s.p_a_mm, kDecimalsPositionMm);
  s.p_b_mm = RoundTo(s.p_b_mm, kDecimalsPositionMm);
  s.sd43920_mm = s.p_a_mm;
  return s;
}

void CheckSlope(const CompensationSegment& s, std::size_t index, double cap) {
  if (!(std::abs(s.sd43910) <= cap))
    throw InputError("segment " + std::to_string(index + 1) + " (t " +
                     FormatSignificant(s.t_a_s, 10) + " to " + FormatSignificant(s.t_b_s, 10) +
                     " s, P " + FormatSignificant(s.p_a_mm, 10) + " to " +
                     FormatSignificant(s.p_b_mm, 10) +
                     " mm): |SD43910| = " + FormatSignificant(std::abs(s.sd43910), 10) +
                     " exceeds the MD32760 cap " + FormatSignificant(cap, 10) +
                     " (the control would limit it silently): raise --md32760 if the machine "
                     "allows, or lower the feed");
}

// Largest |applied - chord| the rounding of the written values can cause, um: half a unit of
// SD43900, half a unit of SD43910 over the whole thread, and the shift of the reference and
// trigger positions by half a unit times the steepest allowed slope (twice: both ends).
double RoundingBudgetUm(double thread_length_mm, double md32760) {
  const double k0 = 0.5 * std::pow(10.0, -kDecimalsSd43900Mm);
  const double slope = 0.5 * std::pow(10.0, -kDecimalsSd43910) * thread_length_mm;
  const double p0 = 2.0 * md32760 * 0.5 * std::pow(10.0, -kDecimalsPositionMm);
  return 1000.0 * (k0 + slope + p0);
}

// One action per segment (the first at the thread start) and one for the restore.
std::size_t SyncIdsNeeded(const CompensationPlan& plan) { return plan.segments.size() + 1; }

}  // namespace

double RoundTo(double x, int decimals) {
  return std::stod(FormatFixed(x, decimals));  // exactly what is printed, read back
}

std::string ToString(ControlDk c) { return c == ControlDk::kAdded ? "added" : "subtracted"; }

ControlDk ParseControlDk(const std::string& text) {
  if (text == "added") return ControlDk::kAdded;
  if (text == "subtracted") return ControlDk::kSubtracted;
  throw InputError("control_dk '" + text +
                   "': must be 'added' (the control adds dK to the position setpoint) or "
                   "'subtracted'");
}

SignConvention ExpectedSign(int direction, ControlDk control_dk) {
  const int s = (control_dk == ControlDk::kAdded ? -1 : 1) * direction;
  return s > 0 ? SignConvention::kAdd : SignConvention::kSubtract;
}

std::string ToString(SignConvention s) { return s == SignConvention::kAdd ? "add" : "subtract"; }

SignConvention ParseSignConvention(const std::string& s) {
  if (s == "subtract") return SignConvention::kSubtract;
  if (s == "add") return SignConvention::kAdd;
  throw InputError("sign convention '" + s + "': must be 'subtract' (dK = -l) or 'add' (dK = +l)");
}

double SignFactor(SignConvention s) { return s == SignConvention::kAdd ? 1.0 : -1.0; }

void CheckAxisName(const std::string& axis, const std::string& field) {
  if (axis.size() > kMaxAxisNameLength)
    throw InputError(field + " = '" + axis.substr(0, kMaxAxisNameLength) + "...': at most " +
                     std::to_string(kMaxAxisNameLength) + " characters");
  if (axis.empty() || !std::isalpha(static_cast<unsigned char>(axis[0])) ||
      !std::all_of(axis.begin(), axis.end(),
                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
    throw InputError(field + " = '" + axis +
                     "': must be an axis name (a letter, then letters, digits or '_')");
}

void PlanOptions::Validate() const {
  CheckRange(tolerance_um, kPlanToleranceRange, "tolerance_um", "plan");
  CheckFinitePositive(check_step_s, "check_step_s");
  CheckAxisName(axis);
  CheckRange(start_position_mm, kAxisPositionRange, "start_position_mm", "plan");
  CheckRange(machine_offset_mm, kAxisPositionRange, "machine_offset_mm", "plan");
  if (direction != 1 && direction != -1)
    throw InputError("direction = " + std::to_string(direction) + ": must be +1 or -1");
  if (!(md32760 > 0 && md32760 <= kMd32760Max))
    throw InputError("md32760 = " + FormatSignificant(md32760, 10) +
                     ": must be within (0, 0.10] (MD32760 range)");
  if (sign != ExpectedSign(direction, control_dk))
    throw InputError("sign '" + ToString(sign) + "' with direction " + std::to_string(direction) +
                     " and control_dk '" + ToString(control_dk) +
                     "': inconsistent; the growth "
                     "points against the travel, so dK = -direction * l if the control adds dK "
                     "to the setpoint and +direction * l if it subtracts it (sign '" +
                     ToString(ExpectedSign(direction, control_dk)) + "' here)");
  if (!(sync_id_first == 0 && sync_id_last == 0) &&
      !(sync_id_first >= 1 && sync_id_first <= sync_id_last && sync_id_last <= kMaxSyncActionId))
    throw InputError("synchronized-action IDs " + std::to_string(sync_id_first) + ".." +
                     std::to_string(sync_id_last) +
                     ": must satisfy 1 <= first <= last <= 255 (or both 0: not set)");
  if (!(start_alarm >= kUserAlarmFirst && start_alarm <= kUserAlarmLast))
    throw InputError("start_alarm " + std::to_string(start_alarm) + ": must be within " +
                     std::to_string(kUserAlarmFirst) + ".." + std::to_string(kUserAlarmLast) +
                     " (user cycle alarms; 60000..64999 belong to Siemens' cycles)");
  if (workpiece_k0_param > 9999 || (workpiece_k0_param >= 0 && drift_alive_param < 0))
    throw InputError("combined with the drift action: workpiece_k0_param " +
                     std::to_string(workpiece_k0_param) +
                     " must be 0..9999 and needs the drift action's liveness slot "
                     "(drift_alive_param, the profile's drift.param_first)");
  if (drift_alive_param > 9999)
    throw InputError("drift_alive_param " + std::to_string(drift_alive_param) +
                     ": must be at most 9999");
  if (!(drift_missing_alarm >= kUserAlarmFirst && drift_missing_alarm <= kUserAlarmLast - 2))
    throw InputError("drift_missing_alarm " + std::to_string(drift_missing_alarm) +
                     ": must be within " + std::to_string(kUserAlarmFirst) + ".." +
                     std::to_string(kUserAlarmLast - 2) +
                     " (user cycle alarms; it and the next two numbers are used)");
  if (drift_alive_param >= 0 && start_alarm >= drift_missing_alarm &&
      start_alarm <= drift_missing_alarm + 2)
    throw InputError("start_alarm " + std::to_string(start_alarm) +
                     " is one of the drift check's alarms " + std::to_string(drift_missing_alarm) +
                     ".." + std::to_string(drift_missing_alarm + 2) +
                     ": each alarm needs its own number");
  if (workpiece_slope_param >= 0 && !(workpiece_k0_param >= 0 && workpiece_slope_param <= 9998 &&
                                      (workpiece_k0_param < workpiece_slope_param ||
                                       workpiece_k0_param > workpiece_slope_param + 1)))
    throw InputError("slope handed to the drift action: workpiece_slope_param " +
                     std::to_string(workpiece_slope_param) +
                     " needs workpiece_k0_param >= 0 outside its two slots (" +
                     std::to_string(workpiece_k0_param) + ") and must be 0..9998");
  if (blank_param >= 0 &&
      !(workpiece_slope_param >= 0 && blank_param <= 9998 &&
        (blank_param + 1 < workpiece_slope_param || blank_param > workpiece_slope_param + 1) &&
        (blank_param + 1 < workpiece_k0_param || blank_param > workpiece_k0_param) &&
        (blank_param + 1 < drift_alive_param || blank_param > drift_alive_param)))
    throw InputError("blank latch: blank_param " + std::to_string(blank_param) +
                     " needs workpiece_slope_param (the drift action owns the slope), must be "
                     "0..9998 and its two slots must not hold a workpiece or liveness slot");
  if (!(save_r_first >= -1 && save_r_first <= 9996))
    throw InputError("save_r_first = " + std::to_string(save_r_first) +
                     ": must be within 0..9996 (R<n>..R<n+3> are used), or -1: not set");
}

double AxisPositionMm(const PlanOptions& o, double axial_feed_mm_s, double t_s) {
  return o.machine_offset_mm + o.start_position_mm +
         static_cast<double>(o.direction) * axial_feed_mm_s * t_s;
}

CompensationPlan BuildPlan(const CurveFunction& curve_um, double axial_feed_mm_s,
                           double thread_length_mm, const PlanOptions& options,
                           const std::vector<double>& forced_times_s) {
  options.Validate();
  CheckFinitePositive(axial_feed_mm_s, "axial_feed_mm_s");
  CheckFinitePositive(thread_length_mm, "thread_length_mm");
  CompensationPlan plan;
  plan.options = options;
  plan.axial_feed_mm_s = axial_feed_mm_s;
  plan.thread_length_mm = thread_length_mm;
  plan.cutting_time_s = thread_length_mm / axial_feed_mm_s;
  const double budget_um = RoundingBudgetUm(thread_length_mm, options.md32760);
  if (!(options.tolerance_um > 2.0 * budget_um))
    throw InputError("tolerance_um = " + FormatSignificant(options.tolerance_um, 10) +
                     ": must exceed " + FormatSignificant(2.0 * budget_um, 10) +
                     " um, twice what rounding the written setting data "
                     "can cost over a " +
                     FormatSignificant(thread_length_mm, 10) + " mm thread");
  BreakpointOptions bo;
  bo.tolerance_um = options.tolerance_um - budget_um;
  bo.check_step_s = options.check_step_s;
  bo.forced_times_s = forced_times_s;
  const Breakpoints bp = ChooseBreakpoints(curve_um, 0.0, plan.cutting_time_s, bo);
  for (std::size_t i = 0; i + 1 < bp.size(); ++i) {
    plan.segments.push_back(MakeSegment(options, axial_feed_mm_s, bp.time_s[i], bp.time_s[i + 1],
                                        bp.value_um[i], bp.value_um[i + 1]));
    CheckSlope(plan.segments.back(), i, options.md32760);
    plan.max_abs_slope = std::max(plan.max_abs_slope, std::abs(plan.segments.back().sd43910));
  }
  plan.point_count = bp.size();
  plan.max_deviation_um = bp.max_deviation_um;
  plan.effective_tolerance_um = bp.effective_tolerance_um;
  plan.uniform_point_count = UniformPointCount(curve_um, 0.0, plan.cutting_time_s, bo);
  return plan;
}

CompensationPlan BuildPlan(const fit::ArctanCurve& curve, double axial_feed_mm_s,
                           double thread_length_mm, const PlanOptions& options) {
  curve.Validate("curve for the compensation plan");
  return BuildPlan([&curve](double t) { return curve.ElongationUm(t); }, axial_feed_mm_s,
                   thread_length_mm, options, {curve.settle_time_s});
}

double AppliedCompensationUm(const CompensationPlan& plan, double axis_position_mm) {
  if (plan.segments.empty()) return 0.0;
  const double d = static_cast<double>(plan.options.direction);
  if (d * (axis_position_mm - plan.segments.front().sd43920_mm) < 0) return 0.0;  // not started
  std::size_t active = 0;
  for (std::size_t i = 0; i < plan.segments.size(); ++i)
    if (d * (axis_position_mm - plan.segments[i].sd43920_mm) >= 0) active = i;
  const CompensationSegment& s = plan.segments[active];
  const double dk_mm = s.sd43900_mm + s.sd43910 * (axis_position_mm - s.sd43920_mm);
  return dk_mm * 1000.0 / SignFactor(plan.options.sign);
}

void ValidatePlan(const CompensationPlan& plan) {
  plan.options.Validate();
  CheckFinitePositive(plan.axial_feed_mm_s, "plan axial_feed_mm_s");
  CheckFinitePositive(plan.thread_length_mm, "plan thread_length_mm");
  if (plan.segments.empty()) throw InputError("plan: no segments");
  const double d = static_cast<double>(plan.options.direction);
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const CompensationSegment& s = plan.segments[i];
    for (double v : {s.t_a_s, s.t_b_s, s.p_a_mm, s.p_b_mm, s.l_a_um, s.l_b_um, s.sd43900_mm,
                     s.sd43910, s.sd43920_mm})
      if (!std::isfinite(v))
        throw InputError("plan segment " + std::to_string(i + 1) + ": a value is not finite");
    if (!(s.t_b_s > s.t_a_s) || !(d * (s.p_b_mm - s.p_a_mm) > 0))
      throw InputError("plan segment " + std::to_string(i + 1) +
                       ": must advance in time and in the direction of travel");
    if (i > 0 && (plan.segments[i - 1].t_b_s != s.t_a_s || plan.segments[i - 1].p_b_mm != s.p_a_mm))
      throw InputError("plan segment " + std::to_string(i + 1) + ": does not start where segment " +
                       std::to_string(i) + " ends");
    CheckSlope(s, i, plan.options.md32760);
  }
}

// --- JSON ----------------------------------------------------------------------------------

void to_json(nlohmann::json& j, const PlanOptions& o) {
  j = nlohmann::json{{"tolerance_um", o.tolerance_um},
                     {"axis", o.axis},
                     {"start_position_mm", o.start_position_mm},
                     {"direction", o.direction},
                     {"machine_offset_mm", o.machine_offset_mm},
                     {"sign", ToString(o.sign)},
                     {"control_dk", ToString(o.control_dk)},
                     {"md32760", o.md32760},
                     {"check_step_s", o.check_step_s},
                     {"sync_id_first", o.sync_id_first},
                     {"sync_id_last", o.sync_id_last},
                     {"save_r_first", o.save_r_first},
                     {"workpiece_k0_param", o.workpiece_k0_param},
                     {"drift_alive_param", o.drift_alive_param},
                     {"drift_missing_alarm", o.drift_missing_alarm},
                     {"workpiece_slope_param", o.workpiece_slope_param},
                     {"blank_param", o.blank_param},
                     {"start_alarm", o.start_alarm}};
}

void from_json(const nlohmann::json& j, PlanOptions& o) {
  RejectUnknownKeys(j, {"tolerance_um",         "axis",
                        "start_position_mm",    "direction",
                        "machine_offset_mm",    "sign",
                        "control_dk",           "md32760",
                        "check_step_s",         "sync_id_first",
                        "sync_id_last",         "save_r_first",
                        "workpiece_k0_param",   "drift_marker_r",
                        "drift_missing_alarm",  "workpiece_slope_param",
                        "drift_slope_marker_r", "drift_alive_param",
                        "start_alarm",          "blank_param"},
                    "plan settings");
  o.tolerance_um = j.at("tolerance_um").get<double>();
  o.axis = j.at("axis").get<std::string>();
  o.start_position_mm = j.at("start_position_mm").get<double>();
  o.direction = j.at("direction").get<int>();
  o.machine_offset_mm = j.at("machine_offset_mm").get<double>();
  o.sign = ParseSignConvention(j.at("sign").get<std::string>());
  o.control_dk = ParseControlDk(j.at("control_dk").get<std::string>());
  o.md32760 = j.at("md32760").get<double>();
  o.check_step_s = j.at("check_step_s").get<double>();
  o.sync_id_first = j.at("sync_id_first").get<int>();
  o.sync_id_last = j.at("sync_id_last").get<int>();
  o.save_r_first = j.at("save_r_first").get<int>();
  o.workpiece_k0_param = j.at("workpiece_k0_param").get<int>();
  o.drift_missing_alarm = j.at("drift_missing_alarm").get<int>();
  // Absent in plans written before the slope hand-over and the liveness check (their
  // drift_marker_r is read over: the check now looks at the running action, not an R marker).
  o.workpiece_slope_param = j.value("workpiece_slope_param", -1);
  o.drift_alive_param = j.value("drift_alive_param", -1);
  o.blank_param = j.value("blank_param", -1);  // absent before the blank latch
  // Absent in plans written before the start check: its documented default.
  o.start_alarm = j.value("start_alarm", kDefaultStartAlarm);
  o.Validate();
}

void to_json(nlohmann::json& j, const CompensationPlan& plan) {
  nlohmann::json segments = nlohmann::json::array();
  for (const CompensationSegment& s : plan.segments)
    segments.push_back({{"t_a_s", s.t_a_s},
                        {"t_b_s", s.t_b_s},
                        {"p_a_mm", s.p_a_mm},
                        {"p_b_mm", s.p_b_mm},
                        {"l_a_um", s.l_a_um},
                        {"l_b_um", s.l_b_um},
                        {"sd43900_mm", s.sd43900_mm},
                        {"sd43910", s.sd43910},
                        {"sd43920_mm", s.sd43920_mm}});
  j = nlohmann::json{{"schema", kPlanSchema},
                     {"schema_version", kPlanSchemaVersion},
                     {"settings", plan.options},
                     {"axial_feed_mm_s", plan.axial_feed_mm_s},
                     {"thread_length_mm", plan.thread_length_mm},
                     {"cutting_time_s", plan.cutting_time_s},
                     {"point_count", plan.point_count},
                     {"uniform_point_count", plan.uniform_point_count},
                     {"max_deviation_um", plan.max_deviation_um},
                     {"effective_tolerance_um", plan.effective_tolerance_um},
                     {"max_abs_sd43910", plan.max_abs_slope},
                     {"units",
                      {{"t", "s"},
                       {"p", "mm (machine coordinates)"},
                       {"l", "um"},
                       {"sd43900", "mm"},
                       {"sd43910", "- (mm/mm)"},
                       {"sd43920", "mm"}}},
                     {"segments", segments}};
}

void from_json(const nlohmann::json& j, CompensationPlan& plan) {
  if (j.at("schema").get<std::string>() != kPlanSchema)
    throw InputError("plan: schema '" + j.at("schema").get<std::string>() + "': expected '" +
                     kPlanSchema + "'");
  if (j.at("schema_version").get<int>() != kPlanSchemaVersion)
    throw InputError("plan: schema_version " + j.at("schema_version").dump() + ": expected " +
                     std::to_string(kPlanSchemaVersion));
  plan = CompensationPlan{};
  plan.options = j.at("settings").get<PlanOptions>();
  plan.axial_feed_mm_s = j.at("axial_feed_mm_s").get<double>();
  plan.thread_length_mm = j.at("thread_length_mm").get<double>();
  plan.cutting_time_s = j.at("cutting_time_s").get<double>();
  plan.point_count = j.at("point_count").get<std::size_t>();
  plan.uniform_point_count = j.at("uniform_point_count").get<std::size_t>();
  plan.max_deviation_um = j.at("max_deviation_um").get<double>();
  plan.effective_tolerance_um = j.at("effective_tolerance_um").get<double>();
  plan.max_abs_slope = j.at("max_abs_sd43910").get<double>();
  for (const auto& s : j.at("segments")) {
    CompensationSegment seg;
    seg.t_a_s = s.at("t_a_s").get<double>();
    seg.t_b_s = s.at("t_b_s").get<double>();
    seg.p_a_mm = s.at("p_a_mm").get<double>();
    seg.p_b_mm = s.at("p_b_mm").get<double>();
    seg.l_a_um = s.at("l_a_um").get<double>();
    seg.l_b_um = s.at("l_b_um").get<double>();
    seg.sd43900_mm = s.at("sd43900_mm").get<double>();
    seg.sd43910 = s.at("sd43910").get<double>();
    seg.sd43920_mm = s.at("sd43920_mm").get<double>();
    plan.segments.push_back(seg);
  }
  ValidatePlan(plan);
}

// --- PLC table -----------------------------------------------------------------------------

namespace {

// One line of a CSV whose cells are already text (fixed decimals per quantity).
std::string CsvLine(const std::vector<std::string>& cells) {
  std::string line;
  for (std::size_t i = 0; i < cells.size(); ++i) line += (i ? "," : "") + cells[i];
  return line + "\n";
}

std::string OneLine(std::string text) {
  for (char& ch : text)
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = ' ';
  return text;
}

// An NC comment from user text: one line of at most 200 characters (an NC line has at most 512).
std::string NcComment(const std::string& text) {
  const std::string line = OneLine(text);
  return line.size() > 200 ? line.substr(0, 197) + "..." : line;
}

double ThreadEndMm(const CompensationPlan& plan) { return plan.segments.back().p_b_mm; }

}  // namespace

std::string FormatPlcCsv(const CompensationPlan& plan, const std::vector<std::string>& provenance) {
  ValidatePlan(plan);
  const PlanOptions& o = plan.options;
  std::string out;
  for (const std::string& p : provenance) out += "#" + SpreadsheetLine(p) + "\n";
  out += "# SINUMERIK 840D temperature compensation, axis " + o.axis +
         ": when the axis (MCS) passes trigger_position_mm in the direction of travel (" +
         (o.direction > 0 ? "+" : "-") +
         "), write SD43900 $SA_TEMP_COMP_ABS_VALUE, SD43910 $SA_TEMP_COMP_SLOPE, SD43920 "
         "$SA_TEMP_COMP_REF_POSITION of that row; before the first row save the three values "
         "found (if an earlier cut never reached its row 'restore', write its saved values back "
         "first), and at the row 'restore' (thread end) write the saved values back\n";
  out += "# start only with the axis before the first row's trigger_position_mm (at or past it "
         "every passed row would be due at once: raise alarm " +
         std::to_string(o.start_alarm) +
         " and change nothing); until the axis reaches it, write nothing\n";
  out += "# sign " + ToString(o.sign) + " (dK = " + (o.sign == SignConvention::kAdd ? "+" : "-") +
         "elongation; control_dk " + ToString(o.control_dk) + ", direction " +
         std::to_string(o.direction) + "), MD32760 cap " + FormatFixed(o.md32760, 4) +
         ", largest |SD43910| " + FormatFixed(plan.max_abs_slope, kDecimalsSd43910) +
         ", tolerance " + FormatFixed(o.tolerance_um, 3) +
         " um, MD32750 $MA_TEMP_COMP_TYPE = 3 required\n";
  out += "# units: t s, positions mm (MCS), elongation um, SD43900 mm, SD43910 -, SD43920 mm\n";
  out += CsvLine({"segment", "trigger_position_mm", "t_a_s", "t_b_s", "p_a_mm", "p_b_mm", "l_a_um",
                  "l_b_um", "sd43900_mm", "sd43910", "sd43920_mm"});
  auto pos = [](double v) { return FormatFixed(v, kDecimalsPositionMm); };
  auto time = [](double v) { return FormatFixed(v, kDecimalsTimeS); };
  auto um = [](double v) { return FormatFixed(v, kDecimalsElongationUm); };
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const CompensationSegment& s = plan.segments[i];
    out += CsvLine({std::to_string(i + 1), pos(s.sd43920_mm), time(s.t_a_s), time(s.t_b_s),
                    pos(s.p_a_mm), pos(s.p_b_mm), um(s.l_a_um), um(s.l_b_um),
                    FormatFixed(s.sd43900_mm, kDecimalsSd43900Mm),
                    FormatFixed(s.sd43910, kDecimalsSd43910), pos(s.sd43920_mm)});
  }
  out += CsvLine({"restore", pos(ThreadEndMm(plan)), time(plan.cutting_time_s), "",
                  pos(ThreadEndMm(plan)), "", "", "", "saved", "saved", "saved"});
  return out;
}

std::string FormatPointsCsv(const CompensationPlan& plan,
                            const std::vector<std::string>& comments) {
  std::string out;
  for (const std::string& c : comments) out += "#" + SpreadsheetLine(c) + "\n";
  out += "time_s,thread_position_mm,elongation_um,sd43900_mm,sd43910,sd43920_mm\n";
  auto travel = [&](double t) {
    return FormatFixed(t * plan.axial_feed_mm_s, kDecimalsPositionMm);
  };
  for (const CompensationSegment& s : plan.segments)
    out += CsvLine({FormatFixed(s.t_a_s, kDecimalsTimeS), travel(s.t_a_s),
                    FormatFixed(s.l_a_um, kDecimalsElongationUm),
                    FormatFixed(s.sd43900_mm, kDecimalsSd43900Mm),
                    FormatFixed(s.sd43910, kDecimalsSd43910),
                    FormatFixed(s.sd43920_mm, kDecimalsPositionMm)});
  if (!plan.segments.empty()) {
    const CompensationSegment& last = plan.segments.back();
    out += CsvLine({FormatFixed(last.t_b_s, kDecimalsTimeS), travel(last.t_b_s),
                    FormatFixed(last.l_b_um, kDecimalsElongationUm), "saved", "saved", "saved"});
  }
  return out;
}

// --- NC programs ---------------------------------------------------------------------------

void CheckProgramName(const std::string& name, const std::string& what) {
  auto letter = [](char c) { return std::isalpha(static_cast<unsigned char>(c)) != 0; };
  const bool ok =
      name.size() >= 2 && name.size() <= kMaxProgramNameLength && letter(name[0]) &&
      letter(name[1]) && std::all_of(name.begin(), name.end(), [&](char c) {
        return letter(c) || std::isdigit(static_cast<unsigned char>(c)) || c == '_';
      });
  if (!ok)
    throw InputError(what + ": program name '" + NcComment(name) +
                     "' is not a SINUMERIK program name: two letters first, then letters, digits "
                     "or '_' (no blanks, no other characters), at most " +
                     std::to_string(kMaxProgramNameLength) +
                     " characters (Siemens, Programming Manual Fundamentals, Program names)");
}

std::string ProgramNameOf(const std::string& path, const std::string& flag) {
  const std::string name = std::filesystem::path(path).stem().string();
  CheckProgramName(name, flag + " '" + NcComment(path) + "'");
  return name;
}

void CheckDistinctProgramNames(const std::string& program, const std::string& reset_program) {
  auto upper = [](std::string t) {
    for (char& c : t) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    return t;
  };
  if (upper(program) == upper(reset_program))
    throw InputError("the program '" + NcComment(program) + "' and its reset program '" +
                     NcComment(reset_program) +
                     "' would be one program on the control (the same name, ignoring case): give "
                     "them different names");
}

std::string CheckOrAlarm(const std::string& condition, int alarm, const std::string& ok_label) {
  return "IF " + condition + " GOTOF " + ok_label + "\nSETAL(" + std::to_string(alarm) +
         ")\nGOTOF " + kProgramEndLabel + "\n" + ok_label + ":\n";
}

namespace {

bool Combined(const PlanOptions& o) { return o.workpiece_k0_param >= 0; }
// The drift action owns SD43910/SD43920 too; the plan hands its slope and reference over.
bool SlopeHandedOver(const PlanOptions& o) { return o.workpiece_slope_param >= 0; }
std::string Param(int n) { return "$AC_PARAM[" + std::to_string(n) + "]"; }
bool Latches(const PlanOptions& o) { return o.blank_param >= 0; }
// The latch of the blank estimate at the thread start, and its neutral value (no blank term)
// written back at the thread end; " <write>" appended to an action's writes, or "".
std::string LatchWrite(const PlanOptions& o) {
  return Latches(o) ? " " + Param(o.blank_param + 1) + "=" + Param(o.blank_param) : "";
}
std::string UnlatchWrite(const PlanOptions& o) {
  return Latches(o) ? " " + Param(o.blank_param + 1) + "=" + FormatFixed(20.0, 4) : "";
}

// Where K0 goes: SD43900 itself, or (combined with the drift action) the $AC_PARAM the drift
// action adds. prefix "$$" in a synchronized action (main run), "$" in the part program.
std::string K0Target(const PlanOptions& o, const std::string& prefix) {
  if (Combined(o)) return "$AC_PARAM[" + std::to_string(o.workpiece_k0_param) + "]";
  return prefix + "SA_TEMP_COMP_ABS_VALUE[" + o.axis + "]";
}

std::string SlopeTarget(const PlanOptions& o, const std::string& prefix) {
  if (SlopeHandedOver(o)) return Param(o.workpiece_slope_param);
  return prefix + "SA_TEMP_COMP_SLOPE[" + o.axis + "]";
}

std::string RefTarget(const PlanOptions& o, const std::string& prefix) {
  if (SlopeHandedOver(o)) return Param(o.workpiece_slope_param + 1);
  return prefix + "SA_TEMP_COMP_REF_POSITION[" + o.axis + "]";
}

std::string SdWrites(const PlanOptions& o, const std::string& prefix, const std::string& k0,
                     const std::string& slope, const std::string& p0) {
  return K0Target(o, prefix) + "=" + k0 + " " + SlopeTarget(o, prefix) + "=" + slope + " " +
         RefTarget(o, prefix) + "=" + p0;
}

std::string CancelIds(const PlanOptions& o) {
  std::string out;
  for (int id = o.sync_id_first; id <= o.sync_id_last; ++id)
    out += "CANCEL(" + std::to_string(id) + ")\n";
  return out;
}

std::string R(int n) { return "R" + std::to_string(n); }

// Part-program lines (preprocessing) that save the found setting data (combined: not SD43900,
// which the drift action owns) and set the marker.
std::string SaveFoundValues(const PlanOptions& o) {
  const std::string& ax = o.axis;
  const int m = o.save_r_first;
  const std::string k0 =
      Combined(o) ? std::string() : R(m) + "=$SA_TEMP_COMP_ABS_VALUE[" + ax + "]\n";
  if (SlopeHandedOver(o)) return "";  // nothing of the control's is written: nothing to save
  const std::string slope = R(m + 1) + "=$SA_TEMP_COMP_SLOPE[" + ax + "]\n" + R(m + 2) +
                            "=$SA_TEMP_COMP_REF_POSITION[" + ax + "]\n";
  return "IF " + R(m + 3) + "<>1\n" + k0 + slope + R(m + 3) + "=1\nENDIF\n";
}

// The value K0 returns to: the saved SD43900, or 0 for the plan's part of the combined K0.
std::string RestoredK0(const PlanOptions& o, const std::string& r_prefix) {
  return Combined(o) ? "0" : r_prefix + R(o.save_r_first);
}
// Slope and reference return to the saved values, or 0 for the plan's handed-over part.
std::string RestoredSlope(const PlanOptions& o, const std::string& r_prefix) {
  return SlopeHandedOver(o) ? "0" : r_prefix + R(o.save_r_first + 1);
}
std::string RestoredRef(const PlanOptions& o, const std::string& r_prefix) {
  return SlopeHandedOver(o) ? "0" : r_prefix + R(o.save_r_first + 2);
}

// The writes that give back what a run found: the slope first, so that, when the saved slope is
// 0, every intermediate state is a constant offset. `r_prefix` "" in the part program.
std::string RestoreWrites(const PlanOptions& o) {
  return SlopeTarget(o, "$") + "=" + RestoredSlope(o, "") + "\n" + RefTarget(o, "$") + "=" +
         RestoredRef(o, "") + "\n" + K0Target(o, "$") + "=" + RestoredK0(o, "") + "\n";
}

// Part-program lines that undo an earlier run which never reached its restore (a cut aborted or a
// power failure mid-cut: its marker R<m+3> is still 1, the setting data hold its segment values):
// the values it saved are written back and the marker cleared, exactly as the reset program
// does, so the approach of this run applies what the control had before that run and the save
// below finds it again. The plan's own $AC_PARAM slots (combined) return to 0 unconditionally:
// nothing else writes them, and before the thread start the plan's part is 0.
std::string UndoEarlierRun(const PlanOptions& o) {
  // Handed over: slope and K0 slots to 0 (slope first); the reference slot may stay, since with
  // both at 0 the plan adds nothing wherever its reference lies.
  if (SlopeHandedOver(o))
    return SlopeTarget(o, "$") + "=0\n" + K0Target(o, "$") + "=0\n" +
           (Latches(o) ? UnlatchWrite(o).substr(1) + "\n" : std::string());
  const int m = o.save_r_first;
  std::string writes = RestoreWrites(o);
  std::string slots;
  if (Combined(o)) {  // K0 is the plan's slot: out of the IF, unconditional
    slots = K0Target(o, "$") + "=" + RestoredK0(o, "") + "\n";
    writes.erase(writes.find(slots), slots.size());
  }
  return slots + "IF " + R(m + 3) + "==1\n" + writes + R(m + 3) + "=0\nENDIF\n";
}

// Combined: refuse to start unless the drift action says it is active (else K0 would be lost).
std::string RequireDriftAction(const PlanOptions& o) {
  if (o.drift_alive_param < 0) return "";
  const std::string alive = Param(o.drift_alive_param);
  const int a = o.drift_missing_alarm;
  std::string out = alive + "=0\nG4 F0.1\nSTOPRE\n";  // a running action writes it again
  if (!Combined(o)) return out + CheckOrAlarm(alive + "==0", a + 1, "WHIRL_NO_DRIFT_ACTION");
  const std::string mode = SlopeHandedOver(o) ? "2" : "1";
  // A plan that latches the blank also runs beside an action without a blank term (mode 2).
  const std::string also = Latches(o) ? "IF " + alive + "==3 GOTOF WHIRL_DRIFT_MODE_OK\n" : "";
  return out + CheckOrAlarm(alive + "<>0", a, "WHIRL_DRIFT_ACTION_RUNS") + also +
         CheckOrAlarm(alive + "==" + mode, a + 2, "WHIRL_DRIFT_MODE_OK");
}

// Refuses to start (before anything is changed) with the axis at or past the thread start, where
// the first action's condition would already hold: every passed action would fire at once.
std::string RequireAxisBeforeStart(const CompensationPlan& plan) {
  const PlanOptions& o = plan.options;
  return "STOPRE\n" + CheckOrAlarm("$AA_IM[" + o.axis + "]" + (o.direction > 0 ? "<" : ">") +
                                       FormatFixed(plan.segments.front().sd43920_mm,
                                                   kDecimalsPositionMm),
                                   o.start_alarm, "WHIRL_AXIS_BEFORE_START");
}

// "MD28254 ... >= n" for the $AC_PARAM slots a plan program uses (none: empty).
std::string AcParamPrerequisite(const PlanOptions& o) {
  int last = std::max(o.drift_alive_param, o.workpiece_k0_param);
  if (SlopeHandedOver(o)) last = std::max(last, o.workpiece_slope_param + 1);
  if (Latches(o)) last = std::max(last, o.blank_param + 1);
  if (last < 0) return "";
  return "; requires MD28254 $MC_MM_NUM_AC_PARAM >= " + std::to_string(last + 1) +
         " ($AC_PARAM up to index " + std::to_string(last) + ")\n";
}

void HeaderControl(std::ostringstream& nc, const CompensationPlan& plan, const NcProgramInfo& info) {
  const PlanOptions& o = plan.options;
  const std::string& ax = o.axis;
  const std::string start = FormatFixed(plan.segments.front().p_a_mm, kDecimalsPositionMm);
  nc << "; start: call it with the axis before the thread start, " << ax
     << (o.direction > 0 ? " < " : " > ") << start << " mm (MCS); at or past it the program raises "
     << "alarm " << o.start_alarm << " (axis at or past the thread start: no resume from "
     << "mid-thread) and changes nothing: run " << info.reset_program_name
     << " (or let this program undo the aborted run when it is called again), move the axis "
        "before the thread start and cut the whole thread again\n";
  if (SlopeHandedOver(o))
    nc << "; before its actions it sets its K0 and slope slots $AC_PARAM["
       << o.workpiece_k0_param << "], [" << o.workpiece_slope_param
       << "] to 0 (values an aborted run may have left there), so the approach applies the drift "
          "action's own value\n";
  else
    nc << "; after an aborted cut or a power failure mid-cut (marker " << R(o.save_r_first + 3)
       << " still 1) it first writes back the setting data that run saved"
       << (Combined(o) ? " and sets $AC_PARAM[" + std::to_string(o.workpiece_k0_param) + "] to 0"
                       : std::string())
       << ", as " << info.reset_program_name
       << " would, so the approach applies what the control had before that run\n";
  nc << "; after a failed check (alarm) the program jumps to " << kProgramEndLabel
     << " and cancels, saves and writes nothing, whatever the alarm's response; if that response "
        "does not stop the program, the calling program goes on without whirl's compensation\n";
  nc << "; until the axis reaches the thread start the control keeps what it applied before the "
        "call; the first segment is written by ID="
     << o.sync_id_first << " at the thread start\n";
  nc << "; requires MD28250 $MC_MM_NUM_SYNC_ELEMENTS room for " << SyncIdsNeeded(plan)
     << " synchronized actions (IDs " << o.sync_id_first << ".."
     << o.sync_id_first + static_cast<int>(SyncIdsNeeded(plan)) - 1
     << ") beside the machine builder's; no FCTDEF (MD28252) used\n";
  nc << AcParamPrerequisite(o);
}

std::string Header(const CompensationPlan& plan, const NcProgramInfo& info) {
  const PlanOptions& o = plan.options;
  const std::string& ax = o.axis;
  const int m = o.save_r_first;
  std::ostringstream nc;
  nc << "; " << info.program_name
     << ": SINUMERIK 840D temperature compensation of the thermal elongation while whirling\n";
  nc << "; generated by whirl plan; curve: "
     << (info.curve_source.empty() ? "(not stated)" : NcComment(info.curve_source)) << "\n";
  nc << "; axis " << ax << ", " << plan.segments.size() << " segments, tolerance "
     << FormatFixed(o.tolerance_um, 3) << " um (largest deviation on the check grid "
     << FormatFixed(plan.max_deviation_um, 3) << " um)\n";
  nc << "; requires MD32750 $MA_TEMP_COMP_TYPE = 3 for axis " << ax
     << " (bit 0 SD43900, bit 1 SD43910/SD43920; power on)\n";
  nc << "; requires MD32760 $MA_COMP_ADD_VELO_FACTOR >= "
     << FormatFixed(plan.max_abs_slope, kDecimalsSd43910)
     << " (largest |SD43910| here); plan checked against " << FormatFixed(o.md32760, 4) << "\n";
  nc << "; sign: " << ToString(o.sign) << " (dK = " << (o.sign == SignConvention::kAdd ? "+" : "-")
     << "elongation/1000 mm; travel " << (o.direction > 0 ? "+" : "-") << ax << ", control_dk "
     << ToString(o.control_dk) << ")\n";
  nc << "; assumptions: constant axial feed " << FormatFixed(plan.axial_feed_mm_s * 60.0, 4)
     << " mm/min; time 0 = start of the cut at " << ax << " = "
     << FormatFixed(plan.segments.front().p_a_mm, kDecimalsPositionMm) << " mm (MCS); thread end "
     << ax << " = " << FormatFixed(ThreadEndMm(plan), kDecimalsPositionMm) << " mm (MCS), "
     << FormatFixed(plan.thread_length_mm, 4) << " mm of travel\n";
  HeaderControl(nc, plan, info);
  nc << "; uses synchronized-action IDs " << o.sync_id_first << ".." << o.sync_id_last;
  if (SlopeHandedOver(o))
    nc << " (cancelled first); no R parameter (nothing of the control's is written)\n";
  else
    nc << " (cancelled first) and " << R(m) << ".." << R(m + 3)
       << " (setting data found before the cut, marker)\n";
  nc << "; restores "
     << (SlopeHandedOver(o) ? "its $AC_PARAM slots to 0" : "the found setting data")
     << " when the axis passes the thread end; call " << info.reset_program_name
     << " after the cutting block (it restores if the axis stopped short) and after an aborted "
        "cut\n";
  nc << "; $AA_IM = actual position in machine coordinates; $$SA_ = write in the main run\n";
  nc << "; call before the cutting block; the ID= actions stay active until the program ends\n";
  if (o.drift_alive_param >= 0)
    nc << "; checks the live drift action (whirl drift nc) by its liveness slot $AC_PARAM["
       << o.drift_alive_param << "] (cleared, 0.1 s dwell, read back): expects "
       << (SlopeHandedOver(o) ? "2"
           : Combined(o)      ? "1"
                              : "0")
       << "; alarm " << o.drift_missing_alarm << " action not running, "
       << o.drift_missing_alarm + 1
       << " action running although this plan writes the setting data itself, "
       << o.drift_missing_alarm + 2 << " action in the other mode\n";
  if (Combined(o))
    nc << "; combined with the drift action: K0 goes to $AC_PARAM[" << o.workpiece_k0_param
       << "], which the drift action adds into SD43900 (its only writer)\n";
  if (SlopeHandedOver(o))
    nc << "; slope handed over too: SD43910 goes to $AC_PARAM[" << o.workpiece_slope_param
       << "] and SD43920 to $AC_PARAM[" << o.workpiece_slope_param + 1
       << "]; the drift action adds the machine's slope and is the only writer of SD43900-43920\n";
  if (Latches(o))
    nc << "; blank latch: at the thread start the first segment copies the drift action's blank "
          "estimate $AC_PARAM["
       << o.blank_param << "] into $AC_PARAM[" << o.blank_param + 1
       << "], which the drift action's slope reads for the whole cut; the thread end writes 20 "
          "back (no blank term); accepts the drift action in mode 2 or 3\n";
  return nc.str();
}

void RequireSyncIds(const PlanOptions& o) {
  if (!o.HasSyncIds())
    throw InputError(
        "NC program: no synchronized-action IDs set: the program cancels every ID of its range, "
        "so it needs the range the machine builder reserved for whirl (the machine profile's "
        "sync_id_first/sync_id_last, or --sync-id-first and --sync-id-last without a profile); "
        "there is no default");
}

void RequireSaveR(const PlanOptions& o) {
  if (!o.HasSaveR() && !SlopeHandedOver(o))
    throw InputError(
        "NC program: no R parameters set: the program saves the setting data it finds in "
        "R<n>..R<n+3>, the user's R parameters, so it needs the ones the machine builder "
        "reserved for whirl (the machine profile's save_r_first, or --save-r-first without a "
        "profile); there is no default");
}

void CheckNames(const NcProgramInfo& info) {
  CheckProgramName(info.program_name, "NC program name");
  CheckProgramName(info.reset_program_name, "reset program name");
  CheckDistinctProgramNames(info.program_name, info.reset_program_name);
}

}  // namespace

std::string FormatNcProgram(const CompensationPlan& plan, const NcProgramInfo& info) {
  ValidatePlan(plan);
  CheckNames(info);
  const PlanOptions& o = plan.options;
  RequireSyncIds(o);
  RequireSaveR(o);
  const std::string& ax = o.axis;
  const std::size_t available = static_cast<std::size_t>(o.sync_id_last - o.sync_id_first + 1);
  if (SyncIdsNeeded(plan) > available)
    throw InputError("plan has " + std::to_string(plan.segments.size()) +
                     " segments: the NC program needs one synchronized-action ID per segment and "
                     "one for the restore at the thread end (" +
                     std::to_string(SyncIdsNeeded(plan)) + "), but the range " +
                     std::to_string(o.sync_id_first) + ".." + std::to_string(o.sync_id_last) +
                     " has " + std::to_string(available) +
                     ": raise the tolerance or widen the ID range");
  const std::string cmp = o.direction > 0 ? ">=" : "<=";
  auto pos = [](double v) { return FormatFixed(v, kDecimalsPositionMm); };
  auto k0 = [](double v) { return FormatFixed(v, kDecimalsSd43900Mm); };
  auto slope = [](double v) { return FormatFixed(v, kDecimalsSd43910); };
  std::string nc = Header(plan, info) + RequireAxisBeforeStart(plan) + RequireDriftAction(o) +
                   CancelIds(o) + "STOPRE\n" + UndoEarlierRun(o) + SaveFoundValues(o);
  // Every segment, the first included, is a position-triggered action: with the axis before the
  // thread start (checked above) nothing of the plan applies until the axis reaches it, so the
  // first segment's slope is never extrapolated to where the axis is parked.
  int id = o.sync_id_first;
  for (std::size_t i = 0; i < plan.segments.size(); ++i, ++id) {
    const CompensationSegment& s = plan.segments[i];
    nc += "ID=" + std::to_string(id) + " WHEN $AA_IM[" + ax + "]" + cmp + pos(s.sd43920_mm) +
          " DO " + SdWrites(o, "$$", k0(s.sd43900_mm), slope(s.sd43910), pos(s.sd43920_mm)) +
          (i == 0 ? LatchWrite(o) : std::string()) + "\n";
  }
  const int m = o.save_r_first;
  nc += "ID=" + std::to_string(id) + " WHEN $AA_IM[" + ax + "]" + cmp + pos(ThreadEndMm(plan)) +
        " DO " + SdWrites(o, "$$", RestoredK0(o, "$"), RestoredSlope(o, "$"), RestoredRef(o, "$")) +
        (SlopeHandedOver(o) ? std::string() : " $" + R(m + 3) + "=0") + UnlatchWrite(o) + "\n";
  nc += std::string(kProgramEndLabel) + ":\nM17\n";
  return nc;
}

std::string FormatNcResetProgram(const PlanOptions& o, const NcProgramInfo& info) {
  o.Validate();
  CheckNames(info);
  RequireSyncIds(o);
  RequireSaveR(o);
  const std::string& ax = o.axis;
  const int m = o.save_r_first;
  std::string nc = "; " + info.reset_program_name +
                   ": restores the SINUMERIK 840D temperature "
                   "compensation of axis " +
                   ax + " after an aborted " + info.program_name + " run\n";
  const std::string writes = RestoreWrites(o);
  if (SlopeHandedOver(o)) {  // only the plan's own $AC_PARAM slots: cleared unconditionally
    nc +=
        "; cancels synchronized actions " + std::to_string(o.sync_id_first) + ".." +
        std::to_string(o.sync_id_last) + ", then sets the plan's K0, slope and reference in " +
        "$AC_PARAM to 0 (the drift action owns SD43900-43920)" +
        (Latches(o) ? " and the blank latch " + Param(o.blank_param + 1) + " to 20 (no blank term)"
                    : std::string()) +
        "\n";
    return nc + CancelIds(o) + "STOPRE\n" + writes +
           (Latches(o) ? UnlatchWrite(o).substr(1) + "\n" : std::string()) + "STOPRE\nM17\n";
  }
  nc += "; cancels synchronized actions " + std::to_string(o.sync_id_first) + ".." +
        std::to_string(o.sync_id_last) + ", then, if " + R(m + 3) +
        " = 1 (whirl's compensation active), writes back the setting data saved in " + R(m) + ".." +
        R(m + 2) + "\n";
  nc += CancelIds(o) + "STOPRE\nIF " + R(m + 3) + "==1\n" + writes;
  nc += R(m + 3) + "=0\nENDIF\nSTOPRE\nM17\n";
  return nc;
}

std::vector<ControlRequirement> PlanRequirements(const CompensationPlan& plan,
                                                 const std::string& program) {
  const PlanOptions& o = plan.options;
  std::vector<ControlRequirement> out;
  ControlRequirement type = MakeRequirement("MD32750 $MA_TEMP_COMP_TYPE", o.axis,
                                            RequirementRule::kBits, RequirementMerge::kUnion, 3, 0,
                                            "SD43900 and SD43910/SD43920 (" + program + ")");
  out.push_back(type);
  ControlRequirement velo = MakeRequirement(
      "MD32760 $MA_COMP_ADD_VELO_FACTOR", o.axis, RequirementRule::kAtLeast, RequirementMerge::kSum,
      plan.max_abs_slope, kDecimalsSd43910, "the largest |SD43910| of " + program);
  out.push_back(velo);
  const auto ids = static_cast<int>(SyncIdsNeeded(plan));
  ControlRequirement sync = MakeRequirement(
      "MD28250 $MC_MM_NUM_SYNC_ELEMENTS", "", RequirementRule::kAtLeast, RequirementMerge::kSum,
      static_cast<double>(ids), 0,
      std::to_string(ids) + " synchronized actions, IDs " + std::to_string(o.sync_id_first) + ".." +
          std::to_string(o.sync_id_first + ids - 1) + " of the range " +
          std::to_string(o.sync_id_first) + ".." + std::to_string(o.sync_id_last) +
          " it cancels first (" + program + ")");
  out.push_back(sync);
  if (!SlopeHandedOver(o) && o.HasSaveR()) {
    const int m = o.save_r_first;
    ControlRequirement r = MakeRequirement(
        "MD28050 $MC_MM_NUM_R_PARAM", "", RequirementRule::kAtLeast, RequirementMerge::kMax,
        static_cast<double>(m + 4), 0,
        R(m) + ".." + R(m + 3) + " (setting data found before the cut, marker; " + program + ")");
    out.push_back(r);
  }
  int last = std::max(o.drift_alive_param, o.workpiece_k0_param);
  if (SlopeHandedOver(o)) last = std::max(last, o.workpiece_slope_param + 1);
  if (Latches(o)) last = std::max(last, o.blank_param + 1);
  if (last >= 0) {
    ControlRequirement ac =
        MakeRequirement("MD28254 $MC_MM_NUM_AC_PARAM", "", RequirementRule::kAtLeast,
                        RequirementMerge::kMax, static_cast<double>(last + 1), 0,
                        "$AC_PARAM up to index " + std::to_string(last) + " (" + program + ")");
    out.push_back(ac);
  }
  return out;
}

}  // namespace whirl::interp
