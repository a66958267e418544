#pragma once
// A hard-whirling job, the manual of the product's screw module: the screw blank, the five network
// inputs and the machine settings, plus the kinematics and groove geometry that follow from them
// (Li, Ma and Jiang's process; docs/simulator.md), and the screw file a shop writes. The plan
// (plan/), the lab's simulator (sim/) and the machine world (machine/) all cut this screw.
//
// Geometry convention used by the whole project: the blank is clamped in the chuck (the FIXED end,
// axial coordinate x = 0 at the chuck face) and free at x = length_mm. The thread starts
// `settings.thread_start_offset_mm` from the free end and is cut at constant axial feed TOWARDS the
// chuck, so after cutting time t the cut point is `axial_feed_mm_s * t` mm along the thread from
// its start, i.e. at x = thread_start_position_mm - axial_feed_mm_s * t from the chuck face.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "core/process.h"

namespace whirl::screw {

/// Largest tool-circle margin, mm: a whirling ring's tool circle only just clears the blank (6 mm
/// on the reference screw); 100 mm would be a ring several screw sizes too large.
inline constexpr double kMaxToolCircleMarginMm = 100;

/// Machine/process settings that are not among the five network inputs.
struct ProcessSettings {
  /// Formed tools on the whirling ring, - (the paper: 6-8 tools).
  int tool_count = 6;
  /// Feed per tooth, mm: the AXIAL advance of the ring relative to the workpiece per tool
  /// engagement, so axial feed v_f = f_z * z * n_ring. INTERPRETATION of the paper's "0.01 mm per
  /// tool" (Li, Ma and Jiang): the circumferential reading (v_f = lead f_z z n_ring / (pi D)) gives
  /// ~1.6 mm/min, a 50 h cut and a curve that settles in hours, contradicting the paper's Fig. 1
  /// (plateau after ~250 s); the axial reading gives 40 mm/min, a ~2 h cut of the 5100 mm thread
  /// and the paper's time scale.
  double feed_per_tooth_mm = 0.01;
  /// Tool-circle diameter minus screw diameter, mm: D_tool = D + margin, in (0,
  /// kMaxToolCircleMarginMm]. Assumption chosen so that the paper's ring speed 667 r/min and
  /// 180 m/min give D_tool = 86 mm for the 80 mm screw.
  double tool_circle_margin_mm = 6.0;
  /// Distance from the free end of the blank to the start of the thread, mm (unthreaded journal).
  double thread_start_offset_mm = 400.0;
  /// Workshop (ambient) temperature at the start of the cut, degC. The blank starts at this
  /// temperature and the finished screw is measured after cooling back to it (elongation
  /// reference).
  double ambient_temperature_c = 20.0;
};

/// One screw job. `process` holds the five network inputs.
struct Screw {
  std::string name;
  ProcessInputs process;
  double length_mm = 0;         ///< total blank length, mm (reference: 6000)
  double thread_length_mm = 0;  ///< threaded length, mm (reference: 5100)
  ProcessSettings settings;
};

/// Ball-groove cross section cut in one pass, from the raceway radius r (assumptions, documented):
/// groove depth h = kGrooveDepthRatio * r (ball centre near the pitch cylinder, contact angle 45
/// deg needs h > 0.29 r); circular-segment profile; the groove width at the surface is w = 2
/// sqrt(r^2 - (r - h)^2); area A = r^2 acos((r-h)/r) - (r-h) sqrt(2 r h - h^2).
struct GrooveGeometry {
  double depth_mm = 0;          ///< h, mm
  double width_mm = 0;          ///< w, mm (also the axial contact width of the heat source)
  double area_mm2 = 0;          ///< A, mm^2
  double land_mm = 0;           ///< lead - w, mm (must be >= kMinLandMm)
  double mean_diameter_mm = 0;  ///< D - h, mm: diameter at the groove's centroid (approx.)
};
inline constexpr double kGrooveDepthRatio = 0.6;  ///< h / r, - (assumption, see GrooveGeometry)
inline constexpr double kMinLandMm = 0.4;  ///< smallest land between grooves, mm (assumption)
inline constexpr double kMaxGrooveDepthFraction = 0.125;  ///< h <= this * D, i.e. root >= 75 % of D

/// Kinematics of the whirling process:
///   D_tool = D + margin;  n_ring = v_c / (pi D_tool);  v_f = f_z z n_ring (axial, see
///   ProcessSettings::feed_per_tooth_mm);  n_workpiece = v_f / lead;  cutting time = thread / v_f.
struct Kinematics {
  double tool_circle_diameter_mm = 0;   ///< D_tool, mm
  double ring_speed_rpm = 0;            ///< cutter ring speed, 1/min
  double workpiece_speed_rpm = 0;       ///< workpiece speed, 1/min
  double axial_feed_mm_s = 0;           ///< v_f, mm/s
  double axial_feed_mm_min = 0;         ///< v_f, mm/min
  double cutting_time_s = 0;            ///< thread_length / v_f, s
  double thread_start_position_mm = 0;  ///< x of the thread start from the chuck face, mm
  double thread_end_position_mm = 0;    ///< x of the thread end (nearest the chuck), mm
  GrooveGeometry groove;
  /// Groove volume removed per second, mm^3/s: A * pi * D_mean * n_workpiece / 60.
  double material_removal_rate_mm3_s = 0;
  /// Cut point measured from the chuck face after cutting time t (clamped to the thread), mm.
  double CutPositionMm(double t_s) const;
};

/// Throws InputError (naming the field, value and rule) for impossible values: process inputs
/// outside the physical limits of core/limits.h (hardness 20-70 HRC, diameter (0, 500] mm, ...),
/// a blank longer than kMaxBlankLengthMm (20 m), non-positive sizes, tool count outside 1-24,
/// a tool-circle margin outside (0, kMaxToolCircleMarginMm] mm, a thread start offset outside
/// [0, kMaxBlankLengthMm] mm,
/// thread longer than the blank minus the offset, a groove wider than lead - kMinLandMm ("ball too
/// large for the lead"), or deeper than kMaxGrooveDepthFraction * D. `what` prefixes messages (e.g.
/// the file name).
void ValidateScrew(const Screw& screw, const std::string& what = "screw");

/// Groove geometry for raceway radius r and lead (no validation).
GrooveGeometry ComputeGroove(double raceway_radius_mm, double pitch_mm, double diameter_mm);

/// Kinematics of a validated screw (calls ValidateScrew; infeasible geometry -> InputError).
Kinematics ComputeKinematics(const Screw& screw);

/// The paper's reference screw: GCr15SiMn, 80 mm x 10 mm lead x 6000 mm, thread 5100 mm, ring
/// 667 r/min (180 m/min on an 86 mm tool circle), 0.01 mm per tool, 6 tools, 62 HRC, raceway radius
/// 3.7 mm (0.52 x a 7.144 mm ball; hardness and raceway radius are not given in the paper).
Screw ReferenceScrew();

/// JSON (schema_version 1): {"schema_version", "name", "hardness_hrc", "diameter_mm", "pitch_mm",
/// "raceway_radius_mm", "cutting_speed_m_min", "length_mm", "thread_length_mm",
/// "process": {"tool_count", "feed_per_tooth_mm", "tool_circle_margin_mm",
/// "thread_start_offset_mm", "ambient_temperature_c"}}. In "process" every key is optional
/// (defaults above); elsewhere all keys are required except "name". Unknown keys are errors.
void to_json(nlohmann::json& j, const Screw& screw);
void from_json(const nlohmann::json& j, Screw& screw);
inline constexpr int kScrewSchemaVersion = 1;

/// Longest screw name in a screw file, characters (it becomes titles, file names and messages).
inline constexpr std::size_t kMaxScrewNameLength = 200;

/// Reads and validates a screw file; InputError names the file, the key, the value and the rule.
Screw ReadScrew(const std::filesystem::path& path);
/// Validates and writes a screw file atomically.
void WriteScrew(const std::filesystem::path& path, const Screw& screw);

}  // namespace whirl::screw
