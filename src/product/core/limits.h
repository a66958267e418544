#pragma once
// Physical and resource limits on every input whirl accepts: a value outside them is
// an InputError naming the file (line), the field, the value and the limit, never a run that
// overflows, allocates without bound or takes hours. Each limit is far outside any real
// hard-whirling job, so it only stops mistakes (a unit slip, a corrupt file, a typo'd exponent).
//
// Process inputs (process tables, screw files, `predict` flags), closed ranges unless noted:
//   hardness_hrc          20 .. 70 HRC       (the Rockwell C scale)
//   diameter_mm           (0, 500] mm        (ball screws reach about 200 mm)
//   pitch_mm              (0, 100] mm        (leads reach about 50 mm)
//   raceway_radius_mm     (0, 50] mm         (balls reach about 50 mm diameter)
//   cutting_speed_m_min   (0, 1000] m/min    (hard whirling runs at 100-300 m/min)
// Targets (process tables with targets):
//   max_elongation_um     0 .. 10000 um      (10 mm: no screw grows that much while cut)
//   settle_time_s         0 .. 1e6 s         (11.6 days)
// Screw blank: length_mm (0, 20000] mm (whirling machines cut up to about 15 m).
// Axis positions (a machine offset, a start position), mm: within +-kMaxAxisPositionMm (100 m).
//
// Range and CheckRange state any such rule once, so a file field (core/json_file.h
// RequireNumberIn) and a command-line flag break it with the same message.
#include <cstdint>
#include <string>

#include "core/process.h"

namespace whirl {

inline constexpr double kMinHardnessHrc = 20, kMaxHardnessHrc = 70;
inline constexpr double kMaxDiameterMm = 500;
inline constexpr double kMaxPitchMm = 100;
inline constexpr double kMaxRacewayRadiusMm = 50;
inline constexpr double kMaxCuttingSpeedMMin = 1000;
inline constexpr double kMaxElongationUm = 10000;
inline constexpr double kMaxSettleTimeS = 1e6;
inline constexpr double kMaxBlankLengthMm = 20000;
/// Largest |axis position| in machine or program coordinates, mm (a 100 m axis): machine offsets,
/// start and reference positions.
inline constexpr double kMaxAxisPositionMm = 100000;
/// Shortest settle time of a curve a plan is built from, s (CheckPlanFeatures).
inline constexpr double kMinPlanSettleTimeS = 1;
/// Smallest plan tolerance, um: 1 nm, the resolution of SD43900 written with 6 decimals of mm
/// (interp::PlanOptions::Validate).
inline constexpr double kMinPlanToleranceUm = 1e-3;

/// A closed range [min, max] of a quantity, or (min, max] when min_open, with its unit and an
/// optional note on why (said after the range in messages).
struct Range {
  double min = 0, max = 0;
  bool min_open = false;
  const char* unit = "";
  const char* note = "";
  bool Contains(double x) const;  ///< false for NaN
  std::string Text() const;       ///< "[0, 1] K", "(0, 500] mm"
};

/// Axis positions (machine offsets, start positions), +-kMaxAxisPositionMm.
inline constexpr Range kAxisPositionRange{-kMaxAxisPositionMm, kMaxAxisPositionMm, false, "mm"};

/// Largest plan tolerance, um: the largest elongation whirl accepts (kMaxElongationUm); a wider
/// band leaves every curve uncompensated.
inline constexpr double kMaxPlanToleranceUm = kMaxElongationUm;
/// The tolerance of a plan, |840D chord - predicted curve| (the --tolerance-um flag and
/// interp::PlanOptions::tolerance_um, one rule).
inline constexpr Range kPlanToleranceRange{kMinPlanToleranceUm, kMaxPlanToleranceUm, false, "um",
                                           "at least 1 nm, the resolution of SD43900"};

/// InputError "<what>: <field> = <value> breaks the rule: must lie in <range> (<note>)" unless
/// range.Contains(x). `what` names the file (and line) or the command; `field` the key or flag.
void CheckRange(double x, const Range& range, const std::string& field, const std::string& what);

/// Checks the five inputs against the ranges above; InputError "<what>: <field> = <value> breaks
/// the rule: <range with unit>" otherwise (`what` names the file and line, or the flag set).
void CheckProcessInputs(const ProcessInputs& inputs, const std::string& what);

/// Checks the two targets against the ranges above (same message shape).
void CheckFeatures(const Features& features, const std::string& what);

/// The features a curve and a plan are built from (`plan`, `curve`): CheckFeatures and a settle
/// time of at least kMinPlanSettleTimeS, so the planner's check grid stays bounded.
void CheckPlanFeatures(const Features& features, const std::string& what);

/// One line per limit above, for --help texts.
std::string ProcessLimitsHelp();

}  // namespace whirl
