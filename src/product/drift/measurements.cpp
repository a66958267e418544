#include "drift/measurements.h"

#include <cmath>

#include "core/error.h"

namespace whirl::drift {

std::string ToString(MeasurementRecord::Kind k) {
  switch (k) {
    case MeasurementRecord::Kind::kLaser:
      return "laser";
    case MeasurementRecord::Kind::kLead:
      return "lead";
    case MeasurementRecord::Kind::kSetupCheck:
      return "setup_check";
    case MeasurementRecord::Kind::kProbe:
      break;
  }
  return "probe";
}

void ShopRecord::Validate() const {
  for (const MeasurementRecord& r : records) {
    const std::string where = "measurement record '" + r.name + "'";
    if (r.log < 0 || r.log >= static_cast<int>(day_logs.size()))
      throw InputError(where + ": day log " + std::to_string(r.log) + " does not exist (" +
                       std::to_string(day_logs.size()) + " logs)");
    const int n = day_logs[static_cast<std::size_t>(r.log)].samples();
    for (std::size_t k = 0; k < r.rows.size(); ++k) {
      const Measurement& m = r.rows[k];
      const std::string row = where + " row " + std::to_string(k + 1);
      if (m.sample < 0 || m.sample >= n)
        throw InputError(row + ": sample " + std::to_string(m.sample) + " outside its day log (" +
                         std::to_string(n) + " samples)");
      if (!std::isfinite(m.value_um) || !std::isfinite(m.z_mm) || !std::isfinite(m.time_min))
        throw InputError(row + ": value, z and time must be finite");
      if (!(m.sigma_um > 0) || !std::isfinite(m.sigma_um))
        throw InputError(row + ": sigma_um must be finite and > 0");
    }
  }
}

}  // namespace whirl::drift
