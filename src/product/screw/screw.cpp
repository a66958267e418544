#include "screw/screw.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/csv.h"
#include "core/error.h"
#include "core/json_file.h"
#include "core/limits.h"
#include "core/numbers.h"

namespace whirl::screw {
namespace {

[[noreturn]] void Fail(const std::string& what, const std::string& field, double value,
                       const std::string& rule) {
  throw InputError(what + ": " + field + " = " + FormatNumber(value) + " breaks the rule: " + rule);
}

void RequirePositive(const std::string& what, const char* field, double value) {
  if (!(value > 0) || !std::isfinite(value)) Fail(what, field, value, "must be a positive number");
}

}  // namespace

double Kinematics::CutPositionMm(double t_s) const {
  const double travel =
      std::clamp(axial_feed_mm_s * t_s, 0.0, thread_start_position_mm - thread_end_position_mm);
  return thread_start_position_mm - travel;
}

GrooveGeometry ComputeGroove(double raceway_radius_mm, double pitch_mm, double diameter_mm) {
  GrooveGeometry g;
  const double r = raceway_radius_mm;
  const double h = kGrooveDepthRatio * r;
  g.depth_mm = h;
  g.width_mm = 2.0 * std::sqrt(std::max(0.0, r * r - (r - h) * (r - h)));
  g.area_mm2 =
      r * r * std::acos((r - h) / r) - (r - h) * std::sqrt(std::max(0.0, 2 * r * h - h * h));
  g.land_mm = pitch_mm - g.width_mm;
  g.mean_diameter_mm = diameter_mm - h;
  return g;
}

void ValidateScrew(const Screw& s, const std::string& what) {
  const ProcessInputs& p = s.process;
  CheckProcessInputs(p, what);  // physical limits of the five inputs (core/limits.h)
  RequirePositive(what, "length_mm", s.length_mm);
  if (s.length_mm > kMaxBlankLengthMm)
    Fail(what, "length_mm", s.length_mm,
         "a blank is at most " + FormatNumber(kMaxBlankLengthMm) +
             " mm long (physical limit, core/limits.h)");
  RequirePositive(what, "thread_length_mm", s.thread_length_mm);
  const ProcessSettings& st = s.settings;
  if (st.tool_count < 1 || st.tool_count > 24)
    Fail(what, "process.tool_count", st.tool_count, "a whirling ring carries 1-24 tools");
  if (!(st.feed_per_tooth_mm > 0 && st.feed_per_tooth_mm <= 1.0))
    Fail(what, "process.feed_per_tooth_mm", st.feed_per_tooth_mm, "must be in (0, 1] mm");
  CheckRange(st.tool_circle_margin_mm, {0, kMaxToolCircleMarginMm, true, "mm"},
             "process.tool_circle_margin_mm", what);
  CheckRange(st.thread_start_offset_mm, {0, kMaxBlankLengthMm, false, "mm"},
             "process.thread_start_offset_mm", what);
  if (!(st.ambient_temperature_c > -50 && st.ambient_temperature_c < 80))
    Fail(what, "process.ambient_temperature_c", st.ambient_temperature_c,
         "a workshop temperature is within -50..80 degC");
  if (s.thread_length_mm + st.thread_start_offset_mm > s.length_mm) {
    std::ostringstream rule;
    rule << "thread_length_mm + process.thread_start_offset_mm ("
         << FormatNumber(s.thread_length_mm + st.thread_start_offset_mm)
         << ") must not exceed length_mm (" << FormatNumber(s.length_mm) << ")";
    Fail(what, "thread_length_mm", s.thread_length_mm, rule.str());
  }
  const GrooveGeometry g = ComputeGroove(p.raceway_radius_mm, p.pitch_mm, p.diameter_mm);
  if (g.land_mm < kMinLandMm) {
    std::ostringstream rule;
    rule << "ball too large for the lead: groove width 2 sqrt(r^2 - (r - h)^2) = "
         << FormatNumber(g.width_mm) << " mm (h = " << kGrooveDepthRatio
         << " r) plus the minimum land " << kMinLandMm
         << " mm must not exceed pitch_mm = " << FormatNumber(p.pitch_mm);
    Fail(what, "raceway_radius_mm", p.raceway_radius_mm, rule.str());
  }
  if (g.depth_mm > kMaxGrooveDepthFraction * p.diameter_mm) {
    std::ostringstream rule;
    rule << "groove too deep for the diameter: depth " << FormatNumber(g.depth_mm)
         << " mm (h = " << kGrooveDepthRatio << " r) must not exceed " << kMaxGrooveDepthFraction
         << " x diameter_mm = " << FormatNumber(kMaxGrooveDepthFraction * p.diameter_mm) << " mm";
    Fail(what, "raceway_radius_mm", p.raceway_radius_mm, rule.str());
  }
}

Kinematics ComputeKinematics(const Screw& s) {
  ValidateScrew(s);
  Kinematics k;
  const ProcessInputs& p = s.process;
  k.tool_circle_diameter_mm = p.diameter_mm + s.settings.tool_circle_margin_mm;
  k.ring_speed_rpm = p.cutting_speed_m_min * 1000.0 / (kPi * k.tool_circle_diameter_mm);
  k.axial_feed_mm_min = s.settings.feed_per_tooth_mm * s.settings.tool_count * k.ring_speed_rpm;
  k.axial_feed_mm_s = k.axial_feed_mm_min / 60.0;
  k.workpiece_speed_rpm = k.axial_feed_mm_min / p.pitch_mm;
  k.cutting_time_s = s.thread_length_mm / k.axial_feed_mm_s;
  k.thread_start_position_mm = s.length_mm - s.settings.thread_start_offset_mm;
  k.thread_end_position_mm = k.thread_start_position_mm - s.thread_length_mm;
  k.groove = ComputeGroove(p.raceway_radius_mm, p.pitch_mm, p.diameter_mm);
  k.material_removal_rate_mm3_s =
      k.groove.area_mm2 * kPi * k.groove.mean_diameter_mm * k.workpiece_speed_rpm / 60.0;
  return k;
}

Screw ReferenceScrew() {
  Screw s;
  s.name = "reference_80x10x6000";
  s.process.hardness_hrc = 62;
  s.process.diameter_mm = 80;
  s.process.pitch_mm = 10;
  s.process.raceway_radius_mm = 3.7;
  s.process.cutting_speed_m_min = 180;
  s.length_mm = 6000;
  s.thread_length_mm = 5100;
  return s;
}

void to_json(nlohmann::json& j, const Screw& s) {
  j = nlohmann::json::object();
  j["schema_version"] = kScrewSchemaVersion;
  j["name"] = s.name;
  const auto values = s.process.ToArray();
  for (int i = 0; i < ProcessInputs::kCount; ++i) j[kInputColumns[i]] = values[i];
  j["length_mm"] = s.length_mm;
  j["thread_length_mm"] = s.thread_length_mm;
  j["process"] = {{"tool_count", s.settings.tool_count},
                  {"feed_per_tooth_mm", s.settings.feed_per_tooth_mm},
                  {"tool_circle_margin_mm", s.settings.tool_circle_margin_mm},
                  {"thread_start_offset_mm", s.settings.thread_start_offset_mm},
                  {"ambient_temperature_c", s.settings.ambient_temperature_c}};
}

namespace {

void FromJsonChecked(const nlohmann::json& j, Screw& s, const std::string& what) {
  RejectUnknownKeys(
      j,
      {"schema_version", "name", "hardness_hrc", "diameter_mm", "pitch_mm", "raceway_radius_mm",
       "cutting_speed_m_min", "length_mm", "thread_length_mm", "process"},
      what);
  const double version = RequireNumber(j, "schema_version", what);
  if (version != kScrewSchemaVersion)
    Fail(what, "schema_version", version,
         "this build reads schema_version " + std::to_string(kScrewSchemaVersion));
  s = Screw{};
  if (j.contains("name")) {
    if (!j.at("name").is_string())
      throw InputError(what + ": 'name' must be a string, got " + j.at("name").dump());
    s.name = j.at("name").get<std::string>();
    if (s.name.size() > kMaxScrewNameLength)
      throw InputError(what + ": 'name' has " + std::to_string(s.name.size()) +
                       " characters; the limit is " + std::to_string(kMaxScrewNameLength));
  }
  std::array<double, ProcessInputs::kCount> values{};
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    values[i] = RequireNumber(j, kInputColumns[i], what);
  s.process = ProcessInputs::FromArray(values);
  s.length_mm = RequireNumber(j, "length_mm", what);
  s.thread_length_mm = RequireNumber(j, "thread_length_mm", what);
  if (j.contains("process")) {
    const nlohmann::json& p = j.at("process");
    const std::string pwhat = what + " (process)";
    RejectUnknownKeys(p,
                      {"tool_count", "feed_per_tooth_mm", "tool_circle_margin_mm",
                       "thread_start_offset_mm", "ambient_temperature_c"},
                      pwhat);
    if (p.contains("tool_count")) {
      const double z = RequireNumber(p, "tool_count", pwhat);
      if (z != std::floor(z) || z < 1 || z > 24)
        Fail(what, "process.tool_count", z, "must be a whole number of tools, 1-24");
      s.settings.tool_count = static_cast<int>(z);
    }
    if (p.contains("feed_per_tooth_mm"))
      s.settings.feed_per_tooth_mm = RequireNumber(p, "feed_per_tooth_mm", pwhat);
    if (p.contains("tool_circle_margin_mm"))
      s.settings.tool_circle_margin_mm = RequireNumber(p, "tool_circle_margin_mm", pwhat);
    if (p.contains("thread_start_offset_mm"))
      s.settings.thread_start_offset_mm = RequireNumber(p, "thread_start_offset_mm", pwhat);
    if (p.contains("ambient_temperature_c"))
      s.settings.ambient_temperature_c = RequireNumber(p, "ambient_temperature_c", pwhat);
  }
  ValidateScrew(s, what);
}

}  // namespace

void from_json(const nlohmann::json& j, Screw& s) { FromJsonChecked(j, s, "screw"); }

Screw ReadScrew(const std::filesystem::path& path) {
  const nlohmann::json j = ReadJsonFile(path);
  Screw s;
  FromJsonChecked(j, s, "screw file '" + path.string() + "'");
  return s;
}

void WriteScrew(const std::filesystem::path& path, const Screw& screw) {
  ValidateScrew(screw, "screw '" + screw.name + "'");
  nlohmann::json j;
  to_json(j, screw);
  WriteJsonFile(path, j);
}

}  // namespace whirl::screw
