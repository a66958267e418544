#include "lead/lead.h"

#include <cmath>

#include "core/atomic_file.h"
#include "core/csv.h"
#include "core/curve.h"
#include "core/error.h"

namespace whirl::lead {

LeadDeviation ReadLeadDeviation(const std::filesystem::path& path) {
  const CurveColumns csv =
      ReadCurveColumns(path, "position_mm", "deviation_um", 2, "a lead-deviation curve");
  LeadDeviation lead;
  lead.position_mm = csv.x;
  lead.deviation_um = csv.y;
  ValidateLeadDeviation(lead, csv.source);
  return lead;
}

void ValidateLeadDeviation(const LeadDeviation& lead, const std::string& what) {
  if (lead.position_mm.size() != lead.deviation_um.size())
    throw InputError(what + ": " + std::to_string(lead.position_mm.size()) + " positions but " +
                     std::to_string(lead.deviation_um.size()) + " deviations");
  if (lead.size() < 2)
    throw InputError(what + ": a lead-deviation curve needs at least 2 points, found " +
                     std::to_string(lead.size()));
  for (std::size_t i = 0; i < lead.size(); ++i) {
    if (!std::isfinite(lead.position_mm[i]) || !std::isfinite(lead.deviation_um[i]))
      throw InputError(what + ": point " + std::to_string(i) + " is not finite (position_mm " +
                       FormatNumber(lead.position_mm[i]) + ", deviation_um " +
                       FormatNumber(lead.deviation_um[i]) + ")");
    if (i > 0 && !(lead.position_mm[i] > lead.position_mm[i - 1]))
      throw InputError(what + ": position_mm must increase strictly (" +
                       FormatNumber(lead.position_mm[i]) + " after " +
                       FormatNumber(lead.position_mm[i - 1]) + " at point " + std::to_string(i) +
                       ")");
    // Physical limits: the metrics stay finite (no overflow in squares and sums, no division by
    // a vanishing span).
    if (std::fabs(lead.position_mm[i]) > kMaxLeadPositionMm)
      throw InputError(what + ": point " + std::to_string(i) +
                       ": position_mm = " + FormatNumber(lead.position_mm[i]) +
                       " breaks the rule: |position| <= " + FormatNumber(kMaxLeadPositionMm) +
                       " mm");
    if (std::fabs(lead.deviation_um[i]) > kMaxLeadDeviationUm)
      throw InputError(what + ": point " + std::to_string(i) +
                       ": deviation_um = " + FormatNumber(lead.deviation_um[i]) +
                       " breaks the rule: |deviation| <= " + FormatNumber(kMaxLeadDeviationUm) +
                       " um");
    if (i > 0 && lead.position_mm[i] - lead.position_mm[i - 1] < kMinLeadSpacingMm)
      throw InputError(what + ": point " + std::to_string(i) + ": position_mm " +
                       FormatNumber(lead.position_mm[i]) + " is closer than " +
                       FormatNumber(kMinLeadSpacingMm) + " mm to the previous " +
                       FormatNumber(lead.position_mm[i - 1]) + " (rule: spacing >= 1 nm)");
  }
}

void WriteLeadDeviation(const std::filesystem::path& path, const LeadDeviation& lead,
                        const std::vector<std::string>& comments) {
  ValidateLeadDeviation(lead, path.string());
  std::vector<std::vector<double>> rows;
  rows.reserve(lead.size());
  for (std::size_t i = 0; i < lead.size(); ++i)
    rows.push_back({lead.position_mm[i], lead.deviation_um[i]});
  WriteFileAtomic(path, FormatCsv({"position_mm", "deviation_um"}, rows, comments));
}

}  // namespace whirl::lead
