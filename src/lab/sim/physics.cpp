#include "sim/physics.h"

#include <cmath>

namespace whirl::sim {

HeatInput ComputeHeatInput(const screw::Screw& screw, const screw::Kinematics& kinematics,
                           const PhysicsConstants& physics) {
  HeatInput h;
  h.chip_thickness_mm = screw.settings.feed_per_tooth_mm;
  const double kc11_n_mm2 =
      physics.kienzle_kc11_at_60hrc_n_mm2 *
      (1.0 + physics.kienzle_hardness_slope_per_hrc * (screw.process.hardness_hrc - 60.0));
  const double kc_n_mm2 = kc11_n_mm2 * std::pow(h.chip_thickness_mm, -physics.kienzle_mc);
  h.specific_energy_j_mm3 = kc_n_mm2 * 1e-3;  // 1 N/mm^2 = 1 N mm / mm^3 = 1e-3 J/mm^3
  h.material_removal_rate_mm3_s = kinematics.material_removal_rate_mm3_s;
  h.cutting_power_w = h.specific_energy_j_mm3 * h.material_removal_rate_mm3_s;
  h.heat_partition =
      physics.heat_partition_at_ref_speed *
      std::pow(screw.process.cutting_speed_m_min / physics.heat_partition_ref_speed_m_min,
               -physics.heat_partition_speed_exponent);
  h.heat_to_workpiece_w = h.heat_partition * h.cutting_power_w;
  h.contact_width_mm = kinematics.groove.width_mm;
  return h;
}

}  // namespace whirl::sim
