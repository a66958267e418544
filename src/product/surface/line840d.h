#pragma once
// The part of a surface a SINUMERIK 840D can apply: temperature compensation is linear per axis
// (Siemens K3 function manual, interp/sinumerik.h), dK = K0 + tan(beta) (P - P0), so at a given
// time the best it can do along one axis is the least-squares line of the error along that axis's
// travel; this reports that line as setting data and what it leaves uncorrected.
//
// The surface must hold the error of the axis being compensated (for example the X positioning
// error measured over the table, or on a whirling machine the Z error along the Z travel with
// `along` = the surface coordinate that Z moves). Samples: a samples x samples grid over the
// surface's measured rectangle (the whole table: every Y position counts equally), or, with
// `at_mm`, one traverse at that fixed other coordinate. Least squares over the samples:
//   E(c) ~ e0 + k (c - c0),  c the coordinate along the axis, c0 the reference position (default
//   the lower end of the travel), k in um/mm.
// Setting data, with the conventions of interp/sinumerik.h (s = +1 add, -1 subtract, default
// subtract; the same reasoning and the same dry-run check on the machine apply):
//   SD43900 $SA_TEMP_COMP_ABS_VALUE   = s e0 / 1000                      mm
//   SD43910 $SA_TEMP_COMP_SLOPE       = s k / 1000                       dimensionless
//   SD43920 $SA_TEMP_COMP_REF_POSITION = machine_offset_mm + c0          mm (MCS)
// so dK(P) = s (e0 + k (c - c0)) / 1000 at P = machine_offset_mm + c.
// MD32760 cap: |SD43910| > md32760 is clamped to +-md32760 (the control would limit it silently);
// e0 is then refitted for that slope, `slope_capped` is set and the uncorrected error includes the
// cost of the cap.
// Uncorrected error = E - line over the samples: max |.| and RMS, um, beside the error itself
// (no compensation) and the line's best constant (SD43900 only, slope 0).
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "interp/sinumerik.h"
#include "surface/surface.h"

namespace whirl::surface {

struct AxisLineOptions {
  char along = 'x';             ///< surface coordinate the axis moves along: 'x' or 'y'
  std::string axis = "X";       ///< 840D axis name in $SA_...[axis] (interp::CheckAxisName)
  std::optional<double> at_mm;  ///< fixed other coordinate (one traverse), mm; none: whole table
  std::optional<double> ref_position_mm;  ///< c0 in surface coordinates, mm; none: travel start
  double machine_offset_mm = 0;           ///< MCS position of the surface's coordinate origin, mm
  interp::SignConvention sign = interp::SignConvention::kSubtract;
  double md32760 = interp::kMd32760Default;     ///< cap on |SD43910|, (0, 0.10]
  int samples = 101;                            ///< per direction, 2..1001
  void Validate(const Surface& surface) const;  ///< InputError naming the option
};

struct AxisLine {
  AxisLineOptions options;
  double travel_min_mm = 0, travel_max_mm = 0;  ///< of the surface coordinate along the axis
  double reference_mm = 0;                      ///< c0
  double slope_um_per_mm = 0;                   ///< k (after the cap)
  double value_at_ref_um = 0;                   ///< e0
  double sd43900_mm = 0, sd43910 = 0, sd43920_mm = 0;
  bool slope_capped = false;
  double uncapped_sd43910 = 0;
  std::size_t sample_count = 0;
  double error_max_abs_um = 0, error_rms_um = 0;              ///< no compensation
  double offset_only_max_abs_um = 0, offset_only_rms_um = 0;  ///< best constant (SD43900 only)
  double uncorrected_max_abs_um = 0, uncorrected_rms_um = 0;  ///< after the line
  /// dK (mm) the control applies at axis position P (MCS), from the SD values only.
  double CompensationMm(double axis_position_mm) const;
};

AxisLine FitAxisLine(const Surface& surface, const AxisLineOptions& options);

nlohmann::json AxisLineToJson(const AxisLine& line);
std::string FormatAxisLineText(const AxisLine& line);

}  // namespace whirl::surface
