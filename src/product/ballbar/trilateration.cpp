#include "ballbar/trilateration.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::ballbar {
namespace {

std::string Lengths(const Eigen::Vector3d& l) {
  return "L1 = " + MessageNumber(l(0)) + " mm, L2 = " + MessageNumber(l(1)) +
         " mm, L3 = " + MessageNumber(l(2)) + " mm";
}

void CheckTriangle(const PivotCentres& b, const GeometryLimits& limits) {
  const double s12 = (b[1] - b[0]).norm(), s23 = (b[2] - b[1]).norm(), s13 = (b[2] - b[0]).norm();
  const double longest = std::max({s12, s23, s13});
  const double area2 = (b[1] - b[0]).cross(b[2] - b[0]).norm();  // twice the area
  const double ratio = longest > 0 ? area2 / (longest * longest) : 0.0;
  if (!(ratio >= limits.min_triangle_ratio))
    throw InputError("pivots nearly collinear or coincident: |B1B2| = " + MessageNumber(s12) +
                     " mm, |B2B3| = " + MessageNumber(s23) + " mm, |B1B3| = " + MessageNumber(s13) +
                     " mm; the triangle's smallest height over its longest side is " +
                     MessageNumber(ratio) + " (rule: at least " +
                     MessageNumber(limits.min_triangle_ratio) +
                     "); spread the pivots into a triangle around the tool ball");
}

}  // namespace

Eigen::Vector3d PivotFrame::ToMachine(const Eigen::Vector3d& local_mm) const {
  return pivots_mm[0] + axes * local_mm;
}

PivotFrame MakePivotFrame(const PivotCentres& pivots_mm, const GeometryLimits& limits) {
  for (const auto& p : pivots_mm)
    if (!p.allFinite()) throw InputError("pivot centre is not a finite number");
  CheckTriangle(pivots_mm, limits);
  PivotFrame f;
  f.pivots_mm = pivots_mm;
  f.limits = limits;
  const Eigen::Vector3d b12 = pivots_mm[1] - pivots_mm[0], b13 = pivots_mm[2] - pivots_mm[0];
  f.lb1_mm = b12.norm();
  f.lb2_mm = (pivots_mm[2] - pivots_mm[1]).norm();
  f.lb3_mm = b13.norm();
  const Eigen::Vector3d ex = b12 / f.lb1_mm;
  const Eigen::Vector3d ey = (b13 - b13.dot(ex) * ex).normalized();
  Eigen::Vector3d ez = ex.cross(ey);
  if (std::abs(ez.z()) < limits.min_normal_z)
    throw InputError("pivots' plane is tilted " +
                     MessageNumber(std::acos(std::abs(ez.z())) * 180 / kPi) +
                     " degrees from the table (rule: its normal within " +
                     MessageNumber(std::acos(limits.min_normal_z) * 180 / kPi) +
                     " degrees of machine Z, so that the tool ball's side of it is +Z)");
  if (ez.z() < 0) ez = -ez;  // the root of eq. 17 is taken on the spindle's side (+Z)
  f.axes.col(0) = ex;
  f.axes.col(1) = ey;
  f.axes.col(2) = ez;
  f.xb_mm = (f.lb3_mm * f.lb3_mm - f.lb2_mm * f.lb2_mm + f.lb1_mm * f.lb1_mm) / (2 * f.lb1_mm);
  f.cb_mm = std::sqrt(std::max(0.0, f.lb3_mm * f.lb3_mm - f.xb_mm * f.xb_mm));  // > 0: checked
  return f;
}

Eigen::Vector3d TrilaterateLocal(const PivotFrame& f, const Eigen::Vector3d& l) {
  if (!l.allFinite() || l.minCoeff() <= 0)
    throw InputError("bar lengths must be positive finite numbers: " + Lengths(l));
  const double lb1 = f.lb1_mm;
  const double x = (l(0) * l(0) - l(1) * l(1) + lb1 * lb1) / (2 * lb1);  // (11)
  const double c1_sq = l(0) * l(0) - x * x;
  if (!(c1_sq > 0))
    throw InputError("inconsistent bar lengths " + Lengths(l) +
                     ": eq. 12 needs L1^2 - x^2 > 0 but it is " + MessageNumber(c1_sq) +
                     " mm^2 (|L1 - L2| must be less than |B1B2| = " + MessageNumber(lb1) +
                     " mm): a wrong pivot number, pivot centre or bar length");
  const double xb = f.xb_mm, cb = f.cb_mm;                      // (13), (14)
  const double d1_sq = c1_sq + (xb - x) * (xb - x);             // (15)
  const double y = (d1_sq - l(2) * l(2) + cb * cb) / (2 * cb);  // (16)
  const double z_sq = c1_sq - y * y;
  if (!(z_sq > 0))
    throw InputError("inconsistent bar lengths " + Lengths(l) +
                     ": eq. 17 needs c1^2 - y^2 > 0 but it is " + MessageNumber(z_sq) +
                     " mm^2 (the three spheres do not meet, or the tool ball lies in the " +
                     "pivots' plane): a wrong pivot number, pivot centre or bar length");
  const double z = std::sqrt(z_sq);  // (17)
  const double ratio = z / l.maxCoeff();
  if (ratio < f.limits.min_height_ratio)
    throw InputError(
        "tool ball only " + MessageNumber(z) + " mm above the pivots' plane (" + Lengths(l) +
        "): height / longest bar = " + MessageNumber(ratio) + " (rule: at least " +
        MessageNumber(f.limits.min_height_ratio) +
        "); z is ill-conditioned there: raise the tool ball or bring the pivots closer");
  return {x, y, z};
}

Eigen::Vector3d Trilaterate(const PivotFrame& frame, const Eigen::Vector3d& lengths_mm) {
  return frame.ToMachine(TrilaterateLocal(frame, lengths_mm));
}

Eigen::Vector3d BarLengths(const PivotCentres& b, const Eigen::Vector3d& p) {
  return {(p - b[0]).norm(), (p - b[1]).norm(), (p - b[2]).norm()};
}

namespace {
Eigen::Matrix3d UnitRows(const PivotCentres& b, const Eigen::Vector3d& p) {
  Eigen::Matrix3d u;
  for (int i = 0; i < 3; ++i) u.row(i) = (p - b[i]).normalized().transpose();
  return u;
}
}  // namespace

Eigen::Matrix3d PositionJacobian(const PivotCentres& b, const Eigen::Vector3d& p) {
  return UnitRows(b, p).inverse();
}

PlacementAdvice AdvisePlacement(const PivotFrame& f, const Eigen::Vector3d& p) {
  PlacementAdvice a;
  const Eigen::Matrix3d u = UnitRows(f.pivots_mm, p);
  const Eigen::Vector3d sv = Eigen::JacobiSVD<Eigen::Matrix3d>(u).singularValues();
  a.condition_number = sv(0) / sv(2);
  a.noise_gain = u.inverse().rowwise().norm();
  const Eigen::Vector3d normal = f.axes.col(2);
  a.height_mm = (p - f.pivots_mm[0]).dot(normal);
  const Eigen::Vector3d foot = p - a.height_mm * normal;
  double bar_sum = 0;
  for (const auto& b : f.pivots_mm) {
    a.mean_radius_mm += (b - foot).norm() / 3;
    bar_sum += (p - b).norm();
  }
  const double bar = bar_sum / 3;
  a.ideal_height_mm = bar / std::sqrt(3.0);
  a.ideal_radius_mm = bar * std::sqrt(2.0 / 3.0);
  a.rating = a.condition_number <= 2 ? "good" : a.condition_number <= 5 ? "fair" : "poor";
  const std::string ideal = "for bars of " + MessageNumber(bar) + " mm the ideal is a height of " +
                            MessageNumber(a.ideal_height_mm) + " mm and pivots " +
                            MessageNumber(a.ideal_radius_mm) +
                            " mm from the tool ball's foot, 120 degrees apart (condition 1)";
  const double shape = a.mean_radius_mm / std::max(a.height_mm, 1e-12);  // ideal sqrt(2)
  std::string what;
  if (a.rating == "good")
    what = "layout is good";
  else if (shape > 2 * std::sqrt(2.0))
    what = "tool ball too low for the pivots' spread: raise it or bring the pivots closer";
  else if (shape < std::sqrt(2.0) / 2)
    what = "pivots too close together for the tool ball's height: spread them out";
  else
    what = "pivots unevenly spread around the tool ball: place them about 120 degrees apart";
  a.advice = what + "; " + ideal;
  return a;
}

}  // namespace whirl::ballbar
