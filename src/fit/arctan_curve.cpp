#include "fit/arctan_curve.h"

#include <cmath>
#include <sstream>

#include "core/error.h"

namespace whirl::fit {

double ArctanCurve::ElongationUm(double t_s) const {
  if (t_s <= 0) return 0.0;
  if (t_s >= settle_time_s) return max_elongation_um;
  return max_elongation_um * std::atan(shape_k * t_s / settle_time_s) / std::atan(shape_k);
}

double ArctanCurve::SlopeUmPerS(double t_s) const {
  if (t_s < 0 || t_s > settle_time_s) return 0.0;
  const double u = shape_k * t_s / settle_time_s;
  return max_elongation_um * shape_k / (settle_time_s * std::atan(shape_k) * (1.0 + u * u));
}

void ArctanCurve::ParameterGradient(double t_s, double* d_l_d_max, double* d_l_d_settle,
                                    double* d_l_d_k) const {
  if (t_s <= 0) {
    *d_l_d_max = *d_l_d_settle = *d_l_d_k = 0.0;
    return;
  }
  if (t_s >= settle_time_s) {
    *d_l_d_max = 1.0;
    *d_l_d_settle = *d_l_d_k = 0.0;
    return;
  }
  const double atan_k = std::atan(shape_k);
  const double r = t_s / settle_time_s;
  const double u = shape_k * r;
  const double atan_u = std::atan(u);
  const double inv = 1.0 / (1.0 + u * u);
  *d_l_d_max = atan_u / atan_k;
  *d_l_d_settle = -max_elongation_um / atan_k * inv * u / settle_time_s;
  *d_l_d_k = max_elongation_um * (r * inv * atan_k - atan_u / (1.0 + shape_k * shape_k)) /
             (atan_k * atan_k);
}

ArctanCurve ArctanCurve::FromFeatures(const Features& features, double shape_k) {
  ArctanCurve c{features.max_elongation_um, features.settle_time_s, shape_k};
  c.Validate("arctan curve from features");
  return c;
}

void ArctanCurve::Validate(const std::string& what) const {
  auto fail = [&](const char* field, double value, const char* rule) {
    std::ostringstream ss;
    ss.precision(17);
    ss << what << ": " << field << " = " << value << ": " << rule;
    throw InputError(ss.str());
  };
  if (!std::isfinite(max_elongation_um) || max_elongation_um < 0)
    fail("max_elongation_um", max_elongation_um, "must be finite and >= 0");
  if (!std::isfinite(settle_time_s) || settle_time_s <= 0)
    fail("settle_time_s", settle_time_s, "must be finite and > 0");
  if (!(shape_k >= kMinShapeK && shape_k <= kMaxShapeK))
    fail("shape_k", shape_k, "must be within [0.001, 1000]");
}

}  // namespace whirl::fit
