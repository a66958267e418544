#pragma once
// All physical constants and process-model relations of the simulator in one place
// (docs/simulator.md). Each constant says whether it comes from a source or is an assumption.
#include "screw/screw.h"

namespace whirl::sim {

/// Material, heat-transfer and cutting constants. Defaults: GCr15SiMn bearing steel.
struct PhysicsConstants {
  // --- GCr15SiMn (handbook: 7800-7830 kg/m^3, 460-475 J/(kg K), 37-40 W/(m K), 11.5-12.5e-6/K)
  double density_kg_m3 = 7810.0;
  double specific_heat_j_kg_k = 470.0;
  double conductivity_w_m_k = 38.0;
  double expansion_per_k = 11.8e-6;  ///< linear expansion coefficient alpha, 1/K

  /// Surface heat-transfer coefficient to ambient, W/(m^2 K): natural convection plus forced
  /// convection by the rotating workpiece and the whirling ring's air flow (handbook range
  /// 10-50 for air; assumption, mid value). Biot = h R / k = 25 * 0.04 / 38 = 0.026 << 0.1 for the
  /// 80 mm screw (0.033 for 100 mm), so the cross section is isothermal to within ~1 % and the 1D
  /// model of the section-mean temperature is exact up to O(Bi) in the loss term.
  double heat_transfer_coefficient_w_m2_k = 25.0;

  // --- Specific cutting energy, Kienzle law (assumption with textbook constants):
  //   k_c = k_c1.1(HRC) * (h_ch / 1 mm)^(-m_c),  k_c1.1(HRC) = k_c1.1,60 * (1 + s (HRC - 60)),
  // with the uncut chip thickness h_ch = feed_per_tooth_mm (axial advance per tool engagement).
  // k_c1.1 ~ 4000 N/mm^2 and m_c ~ 0.25 are typical for hardened bearing steel (Kienzle tables);
  // the hardness slope is an assumption (harder steel, proportionally higher flow stress).
  double kienzle_kc11_at_60hrc_n_mm2 = 4000.0;
  double kienzle_mc = 0.25;
  double kienzle_hardness_slope_per_hrc = 0.03;

  /// Fraction of the cutting power that ends up in the workpiece at the reference cutting speed,
  /// eta_ref, -. THE CALIBRATION CONSTANT (datasets/README.md, "Calibration"): chosen so the
  /// reference screw's plateau is ~15 um (the order of tens of um the paper's lead errors imply).
  /// It is above the 0.1-0.2 ballpark for the cutting zone alone (textbook; 0.2 gives 6.9 um):
  /// it lumps every heat path into the screw the model does not resolve (flank rubbing on the
  /// hardened groove, hot chips falling on the screw, steady-rest friction).
  double heat_partition_at_ref_speed = 0.43;
  double heat_partition_ref_speed_m_min = 180.0;  ///< v_ref of the partition law, m/min
  /// eta(v_c) = eta_ref * (v_c / v_ref)^(-n): faster cutting carries more heat away in the chips
  /// (trend reported by doi:10.1177/16878132231177994; the exponent is an assumption), -.
  double heat_partition_speed_exponent = 0.8;

  double DiffusivityM2PerS() const {
    return conductivity_w_m_k / (density_kg_m3 * specific_heat_j_kg_k);
  }
};

/// Heat input of the cut, from the process model.
struct HeatInput {
  double chip_thickness_mm = 0;            ///< h_ch = f_z, mm
  double specific_energy_j_mm3 = 0;        ///< k_c, J/mm^3 (= N/mm^2 / 1000 ... in J/mm^3)
  double material_removal_rate_mm3_s = 0;  ///< Q_w, mm^3/s (Kinematics)
  double cutting_power_w = 0;              ///< P_c = k_c * Q_w, W
  double heat_partition = 0;               ///< eta(v_c), -
  double heat_to_workpiece_w = 0;          ///< q = eta * P_c, W
  double contact_width_mm = 0;  ///< axial width the heat is spread over = groove width, mm
};

/// Process model: cutting power and the heat that flows into the workpiece.
HeatInput ComputeHeatInput(const screw::Screw& screw, const screw::Kinematics& kinematics,
                           const PhysicsConstants& physics);

}  // namespace whirl::sim
