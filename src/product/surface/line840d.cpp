#include "surface/line840d.h"

#include <algorithm>
#include <cmath>

#include "core/csv.h"
#include "core/error.h"
#include "core/limits.h"
#include "core/numbers.h"

namespace whirl::surface {
namespace {

struct Sample {
  double c, e;  // coordinate along the axis (mm), error (um)
};

std::vector<Sample> Samples(const Surface& s, const AxisLineOptions& o) {
  const Bounds& b = s.bounds;
  const bool x = o.along == 'x';
  const double lo = x ? b.x_min_mm : b.y_min_mm, hi = x ? b.x_max_mm : b.y_max_mm;
  const double olo = x ? b.y_min_mm : b.x_min_mm, ohi = x ? b.y_max_mm : b.x_max_mm;
  std::vector<double> others;
  if (o.at_mm)
    others.push_back(std::clamp(*o.at_mm, olo, ohi));  // Validate allowed kSamePositionMm slack
  else
    for (int i = 0; i < o.samples; ++i) others.push_back(olo + (ohi - olo) * i / (o.samples - 1));
  std::vector<Sample> out;
  for (double other : others)
    for (int k = 0; k < o.samples; ++k) {
      const double c = lo + (hi - lo) * k / (o.samples - 1);
      out.push_back({c, x ? s.Evaluate(c, other) : s.Evaluate(other, c)});
    }
  return out;
}

void Stats(const std::vector<double>& r, double* max_abs, double* rms) {
  double m = 0, sum2 = 0;
  for (double v : r) m = std::max(m, std::abs(v)), sum2 += v * v;
  *max_abs = m;
  *rms = std::sqrt(sum2 / static_cast<double>(r.size()));
}

}  // namespace

void AxisLineOptions::Validate(const Surface& surface) const {
  if (along != 'x' && along != 'y')
    throw InputError(std::string("--along '") + along + "' must be x or y");
  interp::CheckAxisName(axis);
  if (!(md32760 > 0 && md32760 <= interp::kMd32760Max))
    throw InputError("md32760 " + FormatNumber(md32760) + " must be in (0, 0.10]");
  if (samples < 2 || samples > 1001)
    throw InputError("samples " + std::to_string(samples) + " is outside 2..1001");
  CheckRange(machine_offset_mm, kAxisPositionRange, "machine_offset_mm", "surface line");
  const Bounds& b = surface.bounds;
  const bool x = along == 'x';
  if (at_mm) {
    const double lo = x ? b.y_min_mm : b.x_min_mm, hi = x ? b.y_max_mm : b.x_max_mm;
    if (!(*at_mm >= lo - kSamePositionMm && *at_mm <= hi + kSamePositionMm))
      throw InputError("--at-mm " + FormatNumber(*at_mm) + " is outside the measured range " +
                       FormatNumber(lo) + ".." + FormatNumber(hi) + " mm of " + (x ? "y" : "x"));
  }
  if (ref_position_mm &&
      (!std::isfinite(*ref_position_mm) || std::abs(*ref_position_mm) > kMaxCoordinateMm))
    throw InputError("reference position " + FormatNumber(*ref_position_mm) +
                     " must be finite and within +-100000 mm");
  if ((x ? b.x_max_mm - b.x_min_mm : b.y_max_mm - b.y_min_mm) <= 0)
    throw InputError(std::string("the surface has no extent along ") + along);
}

double AxisLine::CompensationMm(double p) const { return sd43900_mm + sd43910 * (p - sd43920_mm); }

AxisLine FitAxisLine(const Surface& surface, const AxisLineOptions& o) {
  o.Validate(surface);
  AxisLine l;
  l.options = o;
  const bool x = o.along == 'x';
  l.travel_min_mm = x ? surface.bounds.x_min_mm : surface.bounds.y_min_mm;
  l.travel_max_mm = x ? surface.bounds.x_max_mm : surface.bounds.y_max_mm;
  l.reference_mm = o.ref_position_mm.value_or(l.travel_min_mm);
  const std::vector<Sample> s = Samples(surface, o);
  l.sample_count = s.size();
  double mc = 0, me = 0;
  for (const auto& p : s) mc += p.c, me += p.e;
  mc /= static_cast<double>(s.size()), me /= static_cast<double>(s.size());
  double sce = 0, scc = 0;
  for (const auto& p : s) sce += (p.c - mc) * (p.e - me), scc += (p.c - mc) * (p.c - mc);
  const double f = interp::SignFactor(o.sign);
  double k = sce / scc;
  l.uncapped_sd43910 = f * k / 1000;
  if (std::abs(l.uncapped_sd43910) > o.md32760) {
    l.slope_capped = true;
    k = std::copysign(o.md32760 * 1000, k);
  }
  l.slope_um_per_mm = k;
  l.value_at_ref_um = me + k * (l.reference_mm - mc);  // least-squares intercept for slope k
  l.sd43900_mm = f * l.value_at_ref_um / 1000;
  l.sd43910 = f * k / 1000;
  l.sd43920_mm = o.machine_offset_mm + l.reference_mm;
  std::vector<double> raw, offset_only, after;
  for (const auto& p : s) {
    raw.push_back(p.e);
    offset_only.push_back(p.e - me);
    after.push_back(p.e - (l.value_at_ref_um + k * (p.c - l.reference_mm)));
  }
  Stats(raw, &l.error_max_abs_um, &l.error_rms_um);
  Stats(offset_only, &l.offset_only_max_abs_um, &l.offset_only_rms_um);
  Stats(after, &l.uncorrected_max_abs_um, &l.uncorrected_rms_um);
  return l;
}

nlohmann::json AxisLineToJson(const AxisLine& l) {
  const auto& o = l.options;
  return {{"schema", "whirl.surface_line"},
          {"schema_version", 1},
          {"axis", o.axis},
          {"along", std::string(1, o.along)},
          {"traverse_at_mm", o.at_mm ? nlohmann::json(*o.at_mm) : nlohmann::json(nullptr)},
          {"sign", interp::ToString(o.sign)},
          {"md32760", o.md32760},
          {"machine_offset_mm", o.machine_offset_mm},
          {"travel_min_mm", l.travel_min_mm},
          {"travel_max_mm", l.travel_max_mm},
          {"reference_mm", l.reference_mm},
          {"slope_um_per_mm", l.slope_um_per_mm},
          {"value_at_reference_um", l.value_at_ref_um},
          {"sd43900_mm", l.sd43900_mm},
          {"sd43910", l.sd43910},
          {"sd43920_mm", l.sd43920_mm},
          {"slope_capped", l.slope_capped},
          {"uncapped_sd43910", l.uncapped_sd43910},
          {"sample_count", l.sample_count},
          {"error_max_abs_um", l.error_max_abs_um},
          {"error_rms_um", l.error_rms_um},
          {"offset_only_max_abs_um", l.offset_only_max_abs_um},
          {"offset_only_rms_um", l.offset_only_rms_um},
          {"uncorrected_max_abs_um", l.uncorrected_max_abs_um},
          {"uncorrected_rms_um", l.uncorrected_rms_um}};
}

std::string FormatAxisLineText(const AxisLine& l) {
  const auto& o = l.options;
  std::string where = o.at_mm ? "the traverse at " + std::string(o.along == 'x' ? "y" : "x") +
                                    " = " + FormatNumber(*o.at_mm) + " mm"
                              : "the whole measured table";
  std::string s = "axis " + o.axis + " along surface " + std::string(1, o.along) + " (" +
                  FormatDecimals(l.travel_min_mm, 1) + ".." + FormatDecimals(l.travel_max_mm, 1) +
                  " mm), least-squares line over " + where + " (" + std::to_string(l.sample_count) +
                  " samples):\n";
  s += "  error ~ " + FormatDecimals(l.value_at_ref_um, 3) + " um + " +
       FormatDecimals(l.slope_um_per_mm, 6) + " um/mm * (" + std::string(1, o.along) + " - " +
       FormatDecimals(l.reference_mm, 1) + " mm)\n";
  s += "  SD43900 $SA_TEMP_COMP_ABS_VALUE[" + o.axis + "]    = " + FormatDecimals(l.sd43900_mm, 6) +
       " mm\n";
  s += "  SD43910 $SA_TEMP_COMP_SLOPE[" + o.axis + "]        = " + FormatDecimals(l.sd43910, 8) +
       (l.slope_capped ? "  (capped by MD32760 = " + FormatDecimals(o.md32760, 4) + "; uncapped " +
                             FormatDecimals(l.uncapped_sd43910, 8) + ")"
                       : std::string()) +
       "\n";
  s += "  SD43920 $SA_TEMP_COMP_REF_POSITION[" + o.axis + "] = " + FormatDecimals(l.sd43920_mm, 4) +
       " mm (MCS)\n";
  s += "  sign " + interp::ToString(o.sign) +
       ": dK = " + (o.sign == interp::SignConvention::kSubtract ? "-" : "+") +
       "line/1000 (check on the machine, interp/sinumerik.h)\n";
  s += "  error without compensation: max " + FormatDecimals(l.error_max_abs_um, 3) + " um, RMS " +
       FormatDecimals(l.error_rms_um, 3) + " um\n";
  s += "  left by SD43900 alone:      max " + FormatDecimals(l.offset_only_max_abs_um, 3) +
       " um, RMS " + FormatDecimals(l.offset_only_rms_um, 3) + " um\n";
  s += "  left by the line (uncorrected by the 840D): max " +
       FormatDecimals(l.uncorrected_max_abs_um, 3) + " um, RMS " +
       FormatDecimals(l.uncorrected_rms_um, 3) + " um\n";
  return s;
}

}  // namespace whirl::surface
