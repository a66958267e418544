#include "fit/arctan_curve.h"

#include <cmath>
#include <limits>

#include "core/error.h"
#include "core/numbers.h"

namespace whirl::fit {

double ArctanCurve::ElongationUm(double t_s) const {
  if (t_s <= 0) return 0.0;
  if (t_s >= settle_time_s) return max_elongation_um;
  const double r = t_s / settle_time_s;
  const double rp = time_exponent == 1.0 ? r : std::pow(r, time_exponent);
  return max_elongation_um * std::atan(shape_k * rp) / std::atan(shape_k);
}

double ArctanCurve::SlopeUmPerS(double t_s) const {
  if (t_s < 0 || t_s > settle_time_s) return 0.0;
  const double scale =
      max_elongation_um * shape_k * time_exponent / (settle_time_s * std::atan(shape_k));
  if (time_exponent == 1.0) {
    const double u = shape_k * t_s / settle_time_s;
    return scale / (1.0 + u * u);
  }
  if (t_s == 0) return max_elongation_um > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  const double r = t_s / settle_time_s;
  const double rp = std::pow(r, time_exponent);
  const double u = shape_k * rp;
  return scale * std::pow(r, time_exponent - 1.0) / (1.0 + u * u);
}

void ArctanCurve::ParameterGradient(double t_s, double* d_l_d_max, double* d_l_d_settle,
                                    double* d_l_d_k, double* d_l_d_p) const {
  if (t_s <= 0 || t_s >= settle_time_s) {
    *d_l_d_max = t_s <= 0 ? 0.0 : 1.0;
    *d_l_d_settle = *d_l_d_k = 0.0;
    if (d_l_d_p != nullptr) *d_l_d_p = 0.0;
    return;
  }
  // l = L atan(u)/atan(k), u = k r^p, r = t/t_s.
  const double p = time_exponent;
  const double atan_k = std::atan(shape_k);
  const double r = t_s / settle_time_s;
  const double rp = p == 1.0 ? r : std::pow(r, p);
  const double u = shape_k * rp;
  const double atan_u = std::atan(u);
  const double inv = 1.0 / (1.0 + u * u);
  *d_l_d_max = atan_u / atan_k;
  // du/dt_s = -p u / t_s
  *d_l_d_settle = -max_elongation_um / atan_k * inv * p * u / settle_time_s;
  // d/dk [atan(k rp)/atan(k)] = (rp inv atan_k - atan_u/(1 + k^2)) / atan_k^2
  *d_l_d_k = max_elongation_um * (rp * inv * atan_k - atan_u / (1.0 + shape_k * shape_k)) /
             (atan_k * atan_k);
  // du/dp = u ln r
  if (d_l_d_p != nullptr) *d_l_d_p = max_elongation_um / atan_k * inv * u * std::log(r);
}

ArctanCurve ArctanCurve::FromFeatures(const Features& features, double shape_k,
                                      double time_exponent) {
  ArctanCurve c{features.max_elongation_um, features.settle_time_s, shape_k, time_exponent};
  c.Validate("arctan curve from features");
  return c;
}

std::string ArctanCurve::Describe() const {
  return "arctan L=" + FormatDecimals(max_elongation_um, 4) +
         " um, t_s=" + FormatDecimals(settle_time_s, 2) + " s, k=" + FormatDecimals(shape_k, 4) +
         ", p=" + FormatDecimals(time_exponent, 4);
}

void to_json(nlohmann::json& j, const ArctanCurve& c) {
  j = {{"model", "arctan"},
       {"formula", kArctanFormula},
       {"max_elongation_um", c.max_elongation_um},
       {"settle_time_s", c.settle_time_s},
       {"shape_k", c.shape_k},
       {"time_exponent", c.time_exponent}};
}

void ArctanCurve::Validate(const std::string& what) const {
  auto fail = [&](const char* field, double value, const char* rule) {
    throw InputError(what + ": " + field + " = " + FormatSignificant(value, 17) + ": " + rule);
  };
  if (!std::isfinite(max_elongation_um) || max_elongation_um < 0)
    fail("max_elongation_um", max_elongation_um, "must be finite and >= 0");
  if (!std::isfinite(settle_time_s) || settle_time_s <= 0)
    fail("settle_time_s", settle_time_s, "must be finite and > 0");
  if (!(shape_k >= kMinShapeK && shape_k <= kMaxShapeK))
    fail("shape_k", shape_k, "must be within [0.001, 1000]");
  if (!(time_exponent >= kMinTimeExponent && time_exponent <= kMaxTimeExponent))
    fail("time_exponent", time_exponent, "must be within [0.5, 1]");
}

}  // namespace whirl::fit
