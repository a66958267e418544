#pragma once
// Spindle-ball position from three ball-bar lengths: the trilateration of Shang, Ruan and
// Zhang ("Double-ball-bar-based thermal errors measurement method for 3-axis CNC machine tool",
// Journal of Tianjin University 39(11), 2006, section 2.4 and Fig. 7).
//
// Set-up. Three pivot balls B1, B2, B3 are fixed on the table; their centres are known in machine
// coordinates (MCS, mm). The spindle holds the tool ball P at one commanded position; the bar is
// moved from pivot to pivot and reads the centre-to-centre lengths L1 = |P B1|, L2 = |P B2|,
// L3 = |P B3| (mm).
//
// Local frame of the paper (Fig. 7): origin B1, x axis along B1 -> B2, B3 in the xy plane on the +y
// side, z normal to the pivots' plane, pointing to the spindle's side (machine +Z: the tool ball is
// above the table). Base lengths LB1 = |B1B2|, LB2 = |B2B3|, LB3 = |B1B3| (mm). Then, exactly:
//   (11) x  = (L1^2 - L2^2 + LB1^2) / (2 LB1)
//   (12) c1 = sqrt(L1^2 - x^2)                 distance of P from the x axis
//   (13) xB = (LB3^2 - LB2^2 + LB1^2) / (2 LB1)  x of B3
//   (14) cB = sqrt(LB3^2 - xB^2)               y of B3
//   (15) d1^2 = c1^2 + (xB - x)^2              squared distance of P from (xB, 0, 0)
//   (16) y  = (d1^2 - L3^2 + cB^2) / (2 cB)
//   (17) z  = sqrt(c1^2 - y^2)                 the root on the spindle's side
// and P in machine coordinates is B1 + x ex + y ey + z ez (ex, ey, ez the local axes in MCS,
// built from the pivots' measured centres: the paper's LB1..LB3 lie in the XY plane; whirl allows
// any plane whose normal is within 60 degrees of machine Z).
//
// Beyond the paper:
// - Jacobian. dL_i = u_i . dP with u_i = (P - B_i) / L_i, so the Jacobian of the position with
//   respect to the lengths is J_P_L = U^-1, U the 3x3 matrix with rows u_i^T (MCS, mm/mm). It is
//   exact for eqs. 11-17 (tests check it against finite differences of them).
// - Degenerate geometry is an InputError, never NaN: pivots nearly collinear or coincident, a
//   pivots' plane steeper than 60 degrees, a negative radicand in eq. 12 or 17 (lengths that
//   cannot meet), and a tool ball too close to the pivots' plane (z / max L below a limit), where
//   the z coordinate is ill-conditioned (its noise gain grows like max L / z).
// - Placement advice from the condition number kappa(U) = sigma_max / sigma_min: kappa = 1 when
//   the three bars are mutually perpendicular. For a bar of length L that is the tool ball at
//   height h = L / sqrt(3) above the pivots' plane and the pivots on a circle of radius
//   r = L sqrt(2/3) = sqrt(2) h around its foot, 120 degrees apart; each axis then has the noise
//   of one reading.
#include <Eigen/Core>
#include <array>
#include <string>

namespace whirl::ballbar {

/// Centres of the pivot balls B1, B2, B3 in machine coordinates, mm.
using PivotCentres = std::array<Eigen::Vector3d, 3>;

/// Limits that turn degenerate geometry into an InputError (dimensionless ratios).
struct GeometryLimits {
  /// Smallest height of the pivot triangle over its longest side (0.05: the pivots are not within
  /// 3 degrees of a line).
  double min_triangle_ratio = 0.05;
  /// Smallest |cos| of the angle between the pivots' plane normal and machine Z (0.5: 60 degrees).
  double min_normal_z = 0.5;
  /// Smallest height of the tool ball above the pivots' plane over the longest bar length (0.05:
  /// the bars at least 3 degrees out of the plane; the z noise gain is then up to about 20).
  double min_height_ratio = 0.05;
};

/// The paper's local frame of three pivots (Fig. 7).
struct PivotFrame {
  PivotCentres pivots_mm{};  ///< B1, B2, B3 in MCS, mm
  Eigen::Matrix3d axes;      ///< columns: local x, y, z axes as unit vectors in MCS
  double lb1_mm = 0;         ///< LB1 = |B1B2|, mm
  double lb2_mm = 0;         ///< LB2 = |B2B3|, mm
  double lb3_mm = 0;         ///< LB3 = |B1B3|, mm
  double xb_mm = 0;          ///< eq. 13: x of B3 in the local frame, mm
  double cb_mm = 0;          ///< eq. 14: y of B3 in the local frame, mm
  GeometryLimits limits;

  /// Local coordinates (x, y, z) of eqs. 11-17 to MCS: B1 + axes * local.
  Eigen::Vector3d ToMachine(const Eigen::Vector3d& local_mm) const;
};

/// Builds the local frame from the pivots' measured centres. InputError for coincident or
/// nearly collinear pivots and for a plane steeper than limits.min_normal_z allows.
PivotFrame MakePivotFrame(const PivotCentres& pivots_mm, const GeometryLimits& limits = {});

/// Eqs. 11-17: local (x, y, z) of the tool ball from L1, L2, L3 (mm). InputError naming the
/// equation, the lengths and the negative value for inconsistent lengths, and for a tool ball
/// closer to the pivots' plane than limits.min_height_ratio allows.
Eigen::Vector3d TrilaterateLocal(const PivotFrame& frame, const Eigen::Vector3d& lengths_mm);

/// Eqs. 11-17 then the frame: the tool ball in MCS, mm.
Eigen::Vector3d Trilaterate(const PivotFrame& frame, const Eigen::Vector3d& lengths_mm);

/// The forward model: L_i = |P - B_i|, mm.
Eigen::Vector3d BarLengths(const PivotCentres& pivots_mm, const Eigen::Vector3d& position_mm);

/// J_P_L = U^-1 (rows of U: u_i = (P - B_i) / L_i), MCS, mm per mm: column i is the move of the
/// tool ball per unit change of L_i.
Eigen::Matrix3d PositionJacobian(const PivotCentres& pivots_mm, const Eigen::Vector3d& position_mm);

/// How well a layout turns bar noise into position noise.
struct PlacementAdvice {
  double condition_number = 0;  ///< kappa(U) = sigma_max / sigma_min, >= 1 (1 is ideal)
  Eigen::Vector3d noise_gain;   ///< per MCS axis: sqrt(sum_i J_ki^2), the position sd per
                                ///< unit sd of each reading (1 in the ideal layout)
  double height_mm = 0;         ///< tool ball above the pivots' plane, mm
  double mean_radius_mm = 0;    ///< mean horizontal distance of the pivots from its foot, mm
  double ideal_height_mm = 0;   ///< L / sqrt(3) for the mean bar length L, mm
  double ideal_radius_mm = 0;   ///< L sqrt(2/3), mm
  std::string rating;           ///< "good" (kappa <= 2), "fair" (<= 5), "poor" (> 5)
  std::string advice;           ///< one sentence: what to move, with the ideal numbers
};

/// Condition number, noise gains and advice for the tool ball at `position_mm` (MCS).
PlacementAdvice AdvisePlacement(const PivotFrame& frame, const Eigen::Vector3d& position_mm);

}  // namespace whirl::ballbar
