#include "interp/sinumerik.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"

namespace whirl::interp {
namespace {

constexpr const char* kPlanSchema = "whirl.plan";
constexpr int kPlanSchemaVersion = 1;
constexpr int kMaxSyncActionId = 255;

std::string Num(double x) {
  std::ostringstream ss;
  ss.precision(10);
  ss << x;
  return ss.str();
}

// Fixed decimals without "-0.000".
std::string Fixed(double x, int decimals) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, x);
  std::string s = buf;
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

void CheckFinitePositive(double v, const std::string& field) {
  if (!std::isfinite(v) || !(v > 0))
    throw InputError(field + " = " + Num(v) + ": must be a positive finite number");
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
  // "+ 0.0" turns -0.0 (subtract of a zero elongation) into 0 for the writers.
  s.sd43900_mm = sign * l_a / 1000.0 + 0.0;
  s.sd43910 = sign * (l_b - l_a) / 1000.0 / (s.p_b_mm - s.p_a_mm) + 0.0;
  s.sd43920_mm = s.p_a_mm;
  return s;
}

void CheckSlope(const CompensationSegment& s, std::size_t index, double cap) {
  if (!(std::abs(s.sd43910) <= cap))
    throw InputError("segment " + std::to_string(index + 1) + " (t " + Num(s.t_a_s) + " to " +
                     Num(s.t_b_s) + " s, P " + Num(s.p_a_mm) + " to " + Num(s.p_b_mm) +
                     " mm): |SD43910| = " + Num(std::abs(s.sd43910)) + " exceeds the MD32760 cap " +
                     Num(cap) +
                     " (the control would limit it silently): raise --md32760 if the machine "
                     "allows, or lower the feed");
}

}  // namespace

std::string ToString(SignConvention s) { return s == SignConvention::kAdd ? "add" : "subtract"; }

SignConvention ParseSignConvention(const std::string& s) {
  if (s == "subtract") return SignConvention::kSubtract;
  if (s == "add") return SignConvention::kAdd;
  throw InputError("sign convention '" + s + "': must be 'subtract' (dK = -l) or 'add' (dK = +l)");
}

double SignFactor(SignConvention s) { return s == SignConvention::kAdd ? 1.0 : -1.0; }

void PlanOptions::Validate() const {
  CheckFinitePositive(tolerance_um, "tolerance_um");
  if (tolerance_um < kMinPlanToleranceUm)
    throw InputError("tolerance_um = " + Num(tolerance_um) + ": must be at least " +
                     Num(kMinPlanToleranceUm) + " um (1 nm, the resolution of SD43900)");
  CheckFinitePositive(check_step_s, "check_step_s");
  if (axis.size() > 32)
    throw InputError("axis = '" + axis.substr(0, 32) + "...': at most 32 characters");
  if (axis.empty() || !std::isalpha(static_cast<unsigned char>(axis[0])) ||
      !std::all_of(axis.begin(), axis.end(),
                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }))
    throw InputError("axis = '" + axis +
                     "': must be an axis name (a letter, then letters, digits or '_')");
  if (!std::isfinite(start_position_mm))
    throw InputError("start_position_mm = " + Num(start_position_mm) + ": must be finite");
  if (!std::isfinite(machine_offset_mm))
    throw InputError("machine_offset_mm = " + Num(machine_offset_mm) + ": must be finite");
  if (direction != 1 && direction != -1)
    throw InputError("direction = " + std::to_string(direction) + ": must be +1 or -1");
  if (!(md32760 > 0 && md32760 <= kMd32760Max))
    throw InputError("md32760 = " + Num(md32760) + ": must be within (0, 0.10] (MD32760 range)");
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
  BreakpointOptions bo;
  bo.tolerance_um = options.tolerance_um;
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
                     {"md32760", o.md32760},
                     {"check_step_s", o.check_step_s}};
}

void from_json(const nlohmann::json& j, PlanOptions& o) {
  RejectUnknownKeys(j,
                    {"tolerance_um", "axis", "start_position_mm", "direction", "machine_offset_mm",
                     "sign", "md32760", "check_step_s"},
                    "plan settings");
  o.tolerance_um = j.at("tolerance_um").get<double>();
  o.axis = j.at("axis").get<std::string>();
  o.start_position_mm = j.at("start_position_mm").get<double>();
  o.direction = j.at("direction").get<int>();
  o.machine_offset_mm = j.at("machine_offset_mm").get<double>();
  o.sign = ParseSignConvention(j.at("sign").get<std::string>());
  o.md32760 = j.at("md32760").get<double>();
  o.check_step_s = j.at("check_step_s").get<double>();
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

std::string FormatPlcCsv(const CompensationPlan& plan, const std::vector<std::string>& provenance) {
  std::vector<std::string> comments = provenance;
  const PlanOptions& o = plan.options;
  comments.push_back(
      " SINUMERIK 840D temperature compensation, axis " + o.axis +
      ": when the axis (MCS) passes trigger_position_mm in the direction of travel (" +
      (o.direction > 0 ? "+" : "-") +
      "), write SD43900 $SA_TEMP_COMP_ABS_VALUE, SD43910 $SA_TEMP_COMP_SLOPE, "
      "SD43920 $SA_TEMP_COMP_REF_POSITION of that row");
  comments.push_back(" sign " + ToString(o.sign) +
                     " (dK = " + (o.sign == SignConvention::kAdd ? "+" : "-") +
                     "elongation), MD32760 cap " + Num(o.md32760) + ", largest |SD43910| " +
                     Num(plan.max_abs_slope) + ", tolerance " + Num(o.tolerance_um) +
                     " um, MD32750 $MA_TEMP_COMP_TYPE = 3 required");
  comments.push_back(
      " units: t s, positions mm (MCS), elongation um, SD43900 mm, SD43910 -, SD43920 mm");
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < plan.segments.size(); ++i) {
    const CompensationSegment& s = plan.segments[i];
    rows.push_back({static_cast<double>(i + 1), s.p_a_mm, s.t_a_s, s.t_b_s, s.p_a_mm, s.p_b_mm,
                    s.l_a_um, s.l_b_um, s.sd43900_mm, s.sd43910, s.sd43920_mm});
  }
  return FormatCsv({"segment", "trigger_position_mm", "t_a_s", "t_b_s", "p_a_mm", "p_b_mm",
                    "l_a_um", "l_b_um", "sd43900_mm", "sd43910", "sd43920_mm"},
                   rows, comments);
}

// --- NC program ----------------------------------------------------------------------------

std::string FormatNcProgram(const CompensationPlan& plan, const NcProgramInfo& info) {
  ValidatePlan(plan);
  const PlanOptions& o = plan.options;
  const std::string& ax = o.axis;
  if (plan.segments.size() - 1 > static_cast<std::size_t>(kMaxSyncActionId))
    throw InputError("plan has " + std::to_string(plan.segments.size()) +
                     " segments: the NC program needs one synchronized action ID per segment after "
                     "the first and IDs end at " +
                     std::to_string(kMaxSyncActionId) + ": raise the tolerance");
  const std::string cmp = o.direction > 0 ? ">=" : "<=";
  std::ostringstream nc;
  nc << "; " << info.program_name
     << ": SINUMERIK 840D temperature compensation of the thermal elongation while whirling\n";
  nc << "; generated by whirl plan; curve: "
     << (info.curve_source.empty() ? "(not stated)" : info.curve_source) << "\n";
  nc << "; axis " << ax << ", " << plan.segments.size() << " segments, tolerance "
     << Fixed(o.tolerance_um, 3) << " um (largest deviation on the check grid "
     << Fixed(plan.max_deviation_um, 3) << " um)\n";
  nc << "; requires MD32750 $MA_TEMP_COMP_TYPE = 3 for axis " << ax
     << " (bit 0 SD43900, bit 1 SD43910/SD43920; power on)\n";
  nc << "; requires MD32760 $MA_COMP_ADD_VELO_FACTOR >= " << Fixed(plan.max_abs_slope, 8)
     << " (largest |SD43910| here); plan checked against " << Fixed(o.md32760, 4) << "\n";
  nc << "; sign convention: " << ToString(o.sign)
     << " (dK = " << (o.sign == SignConvention::kAdd ? "+" : "-") << "elongation/1000 mm)\n";
  nc << "; assumptions: constant axial feed " << Fixed(plan.axial_feed_mm_s * 60.0, 4)
     << " mm/min; time 0 = start of the cut at " << ax << " = "
     << Fixed(AxisPositionMm(o, plan.axial_feed_mm_s, 0.0), 4) << " mm (MCS); travel "
     << (o.direction > 0 ? "+" : "-") << ax << " over " << Fixed(plan.thread_length_mm, 4)
     << " mm\n";
  nc << "; $AA_IM = actual position in machine coordinates; $$SA_ = write in the main run\n";
  nc << "; call before the cutting block; the ID= actions stay active until the program ends\n";
  const CompensationSegment& first = plan.segments.front();
  nc << "STOPRE\n";
  nc << "$SA_TEMP_COMP_ABS_VALUE[" << ax << "]=" << Fixed(first.sd43900_mm, 6) << "\n";
  nc << "$SA_TEMP_COMP_SLOPE[" << ax << "]=" << Fixed(first.sd43910, 8) << "\n";
  nc << "$SA_TEMP_COMP_REF_POSITION[" << ax << "]=" << Fixed(first.sd43920_mm, 4) << "\n";
  nc << "STOPRE\n";
  for (std::size_t i = 1; i < plan.segments.size(); ++i) {
    const CompensationSegment& s = plan.segments[i];
    nc << "ID=" << i << " WHEN $AA_IM[" << ax << "]" << cmp << Fixed(s.sd43920_mm, 4)
       << " DO $$SA_TEMP_COMP_ABS_VALUE[" << ax << "]=" << Fixed(s.sd43900_mm, 6)
       << " $$SA_TEMP_COMP_SLOPE[" << ax << "]=" << Fixed(s.sd43910, 8)
       << " $$SA_TEMP_COMP_REF_POSITION[" << ax << "]=" << Fixed(s.sd43920_mm, 4) << "\n";
  }
  nc << "M17\n";
  return nc.str();
}

}  // namespace whirl::interp
