#pragma once
// A lead (travel) deviation curve along a ball-screw thread, the manual of the product's lead
// module (with metrics.h, the ISO 3408-3 metrics, and iso3408.h, the class reached; `whirl
// lead-report`): measured on the machine after cooling (CSV `position_mm,deviation_um`), or
// simulated by the lab's compare/cut.h.
//
// Sign convention (whole project): travel deviation = actual travel minus specified travel, both
// measured from the thread start (the free end, where cutting begins) towards the chuck, in um.
// Positive = the groove lies further from the thread start than specified (the lead is long there).
// ISO 3408-3 ("travel deviation = actual minus specified travel").
#include <filesystem>
#include <string>
#include <vector>

namespace whirl::lead {

struct LeadDeviation {
  std::vector<double> position_mm;   ///< along the thread from its start, strictly increasing, mm
  std::vector<double> deviation_um;  ///< travel deviation at that position, um (sign: see above)
  std::size_t size() const { return position_mm.size(); }
};

/// Physical limits of a lead-deviation curve (so every metric stays finite): |position| at most
/// 1e6 mm (1 km), positions at least 1e-6 mm (1 nm) apart, |deviation| at most 1e6 um (1 m).
inline constexpr double kMaxLeadPositionMm = 1e6;
inline constexpr double kMinLeadSpacingMm = 1e-6;
inline constexpr double kMaxLeadDeviationUm = 1e6;

/// Reads a measured lead CSV: header with `position_mm` and `deviation_um` (other columns are
/// ignored), '#' comment lines allowed. Rejects (InputError naming file and line): fewer than 2
/// rows, positions not strictly increasing, non-finite cells, missing columns, values beyond the
/// limits above (ValidateLeadDeviation).
LeadDeviation ReadLeadDeviation(const std::filesystem::path& path);

/// Checks the invariants above (same sizes, >= 2 points, strictly increasing finite positions,
/// finite deviations, the limits above); `what` names the curve in the InputError.
void ValidateLeadDeviation(const LeadDeviation& lead, const std::string& what);

/// Writes `position_mm,deviation_um` with '#' provenance comments, atomically.
void WriteLeadDeviation(const std::filesystem::path& path, const LeadDeviation& lead,
                        const std::vector<std::string>& comments = {});

}  // namespace whirl::lead
