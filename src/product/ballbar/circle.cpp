#include "ballbar/circle.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>

#include "core/csv.h"
#include "core/error.h"
#include "core/numbers.h"

namespace whirl::ballbar {
namespace {

constexpr double kDeg = kPi / 180;

CircleTrace TraceFromTable(const CsvTable& t) {
  for (const auto& name : t.header)
    if (name != "angle_deg" && name != "deviation_um")
      throw InputError(t.source + ": unknown column '" + name +
                       "' (allowed: angle_deg, deviation_um)");
  CircleTrace c;
  c.source = t.source;
  c.comments = t.comments;
  c.angle_deg = t.IncreasingColumn("angle_deg");
  c.deviation_um = t.Column("deviation_um");
  if (c.angle_deg.size() > kMaxTraceSamples)
    throw InputError(t.source + ": " + std::to_string(c.angle_deg.size()) +
                     " samples, more than the " + std::to_string(kMaxTraceSamples) + " accepted");
  for (std::size_t i = 0; i < c.deviation_um.size(); ++i)
    if (std::abs(c.deviation_um[i]) > 10000)
      throw InputError(t.source + ":" + std::to_string(t.line_numbers[i]) +
                       ": column 'deviation_um': " + MessageNumber(c.deviation_um[i]) +
                       " um is beyond +-10000 um (a deviation, not a radius?)");
  return c;
}

}  // namespace

std::string ToString(Plane p) {
  switch (p) {
    case Plane::kXY:
      return "XY";
    case Plane::kXZ:
      return "XZ";
    case Plane::kYZ:
      return "YZ";
  }
  return "?";
}

Plane ParsePlane(const std::string& s) {
  std::string u = s;
  for (auto& ch : u) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
  if (u == "XY") return Plane::kXY;
  if (u == "XZ") return Plane::kXZ;
  if (u == "YZ") return Plane::kYZ;
  throw InputError("plane '" + s + "' is not XY, XZ or YZ");
}

CircleTrace ParseCircleTrace(const std::string& text, const std::string& source) {
  return TraceFromTable(ParseCsv(text, source));
}

CircleTrace ReadCircleTrace(const std::filesystem::path& path) {
  return TraceFromTable(ReadCsv(path));
}

std::string FormatCircleTrace(const CircleTrace& c) {
  std::vector<std::vector<double>> rows;
  for (std::size_t i = 0; i < c.angle_deg.size(); ++i)
    rows.push_back({c.angle_deg[i], c.deviation_um[i]});
  return FormatCsv({"angle_deg", "deviation_um"}, rows, c.comments);
}

void CircleOptions::Validate() const {
  if (!(radius_mm >= 1 && radius_mm <= 2000))
    throw InputError("radius_mm = " + MessageNumber(radius_mm) + ": must be in [1, 2000] mm");
  for (double p : {cyclic_period_1_mm, cyclic_period_2_mm})
    if (!(p == 0 || (p >= 0.1 && p <= 1000)))
      throw InputError("cyclic period = " + MessageNumber(p) +
                       " mm: must be 0 (not fitted) or in [0.1, 1000] mm");
  if (!(std::abs(spindle_tram_urad) <= 1e5))
    throw InputError("spindle_tram_urad = " + MessageNumber(spindle_tram_urad) +
                     ": must be within +-1e5 urad");
  if (spindle_tram_urad != 0 && plane != Plane::kXZ)
    throw InputError("spindle_tram_urad applies to the XZ plane only (plane " + ToString(plane) +
                     ")");
}

namespace {

struct Design {
  Eigen::MatrixXd a;
  std::vector<std::string> names;
  int cyclic1 = -1, cyclic2 = -1;  // first column of each cyclic pair, or -1
};

Design BuildDesign(const CircleTrace& c, const CircleOptions& o) {
  const Eigen::Index n = static_cast<Eigen::Index>(c.angle_deg.size());
  Design d;
  d.names = {"radius offset", "centre offset 1", "centre offset 2", "cos 2theta", "sin 2theta"};
  int cols = 5;
  if (o.cyclic_period_1_mm > 0) d.cyclic1 = cols, cols += 2;
  if (o.cyclic_period_2_mm > 0) d.cyclic2 = cols, cols += 2;
  d.a.resize(n, cols);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double th = c.angle_deg[i] * kDeg, ct = std::cos(th), st = std::sin(th);
    d.a.row(i).head(5) << 1, ct, st, std::cos(2 * th), std::sin(2 * th);
    if (d.cyclic1 >= 0) {
      const double k = 2 * kPi / o.cyclic_period_1_mm, u = o.radius_mm * ct;
      d.a(i, d.cyclic1) = ct * std::sin(k * u);
      d.a(i, d.cyclic1 + 1) = ct * std::cos(k * u);
    }
    if (d.cyclic2 >= 0) {
      const double k = 2 * kPi / o.cyclic_period_2_mm, v = o.radius_mm * st;
      d.a(i, d.cyclic2) = st * std::sin(k * v);
      d.a(i, d.cyclic2 + 1) = st * std::cos(k * v);
    }
  }
  return d;
}

void CheckSeparable(const Design& d, const std::string& source) {
  Eigen::MatrixXd scaled = d.a;
  for (Eigen::Index j = 0; j < scaled.cols(); ++j) scaled.col(j) /= scaled.col(j).norm();
  const Eigen::VectorXd sv = Eigen::JacobiSVD<Eigen::MatrixXd>(scaled).singularValues();
  const double ratio = sv(sv.size() - 1) / sv(0);
  if (!(ratio > 1e-4))
    throw InputError(source +
                     ": the trace cannot separate the fitted terms (smallest/largest "
                     "singular value " +
                     MessageNumber(ratio) +
                     ", rule: above 1e-4); a cyclic period far "
                     "longer than the radius mimics the centre offset: check --cyclic-period-1-mm "
                     "and --cyclic-period-2-mm");
}

// Amplitude and phase of a sin + b cos with their sd from the 2x2 covariance.
void Cyclic(const Eigen::VectorXd& x, const Eigen::MatrixXd& cov, int j, double* amp, double* phase,
            double* amp_sd) {
  const double a = x(j), b = x(j + 1);
  *amp = std::hypot(a, b);
  *phase = std::atan2(b, a) / kDeg;
  Eigen::Vector2d g(a, b);
  g /= std::max(*amp, 1e-300);
  *amp_sd = std::sqrt(std::max(0.0, g.dot(cov.block(j, j, 2, 2) * g)));
}

}  // namespace

CircleDiagnostics FitCircle(const CircleTrace& c, const CircleOptions& o) {
  o.Validate();
  const int n = static_cast<int>(c.angle_deg.size());
  if (n < 16)
    throw InputError(c.source + ": " + std::to_string(n) + " samples (rule: at least 16)");
  const double span = c.angle_deg.back() - c.angle_deg.front();
  if (span < 180 - 1e-9 || span > 360 + 1e-9)
    throw InputError(c.source + ": the trace spans " + MessageNumber(span) +
                     " degrees (rule: 180 to 360 degrees, a semicircle or a full circle)");
  const Design d = BuildDesign(c, o);
  CheckSeparable(d, c.source);
  const Eigen::Map<const Eigen::VectorXd> y(c.deviation_um.data(), n);
  const Eigen::VectorXd x = d.a.colPivHouseholderQr().solve(y);
  const Eigen::VectorXd res = y - d.a * x;
  const int p = static_cast<int>(d.a.cols());
  const double sigma2 = n > p ? res.squaredNorm() / (n - p) : 0.0;
  const Eigen::MatrixXd cov = sigma2 * (d.a.transpose() * d.a).inverse();
  auto sd = [&](int j) { return std::sqrt(std::max(0.0, cov(j, j))); };

  CircleDiagnostics out;
  out.plane = o.plane;
  out.radius_mm = o.radius_mm;
  out.samples = n;
  out.span_deg = span;
  const std::string a1(1, ToString(o.plane)[0]), a2(1, ToString(o.plane)[1]);
  const double per_m = 2000 / o.radius_mm;  // um coefficient -> um/m (or urad)
  out.radius_offset_um = x(0);
  out.centre_offset_1_um = x(1);
  out.centre_offset_2_um = x(2);
  out.scale_mismatch_um_per_m = per_m * x(3);
  out.squareness_urad = per_m * x(4);
  out.terms = {
      {"radius offset", x(0), sd(0), "um"},
      {"centre offset " + a1, x(1), sd(1), "um"},
      {"centre offset " + a2, x(2), sd(2), "um"},
      {"scale mismatch " + a1 + "-" + a2, out.scale_mismatch_um_per_m, per_m * sd(3), "um/m"},
      {"squareness " + a1 + a2, out.squareness_urad, per_m * sd(4), "urad"}};
  if (o.plane == Plane::kXZ) {
    out.parallelism_urad = out.squareness_urad - o.spindle_tram_urad;
    out.terms.push_back(
        {"parallelism Z travel / spindle", out.parallelism_urad, per_m * sd(4), "urad"});
  }
  double asd = 0;
  if (d.cyclic1 >= 0) {
    Cyclic(x, cov, d.cyclic1, &out.cyclic_amplitude_1_um, &out.cyclic_phase_1_deg, &asd);
    out.terms.push_back({"cyclic amplitude " + a1, out.cyclic_amplitude_1_um, asd, "um"});
  }
  if (d.cyclic2 >= 0) {
    Cyclic(x, cov, d.cyclic2, &out.cyclic_amplitude_2_um, &out.cyclic_phase_2_deg, &asd);
    out.terms.push_back({"cyclic amplitude " + a2, out.cyclic_amplitude_2_um, asd, "um"});
  }
  out.residual_rms_um = std::sqrt(res.squaredNorm() / n);
  out.residual_max_um = res.cwiseAbs().maxCoeff();
  const Eigen::VectorXd centred = y - d.a.leftCols(3).rightCols(2) * x.segment(1, 2);
  out.circular_deviation_um = centred.maxCoeff() - centred.minCoeff();
  return out;
}

nlohmann::json ToJson(const CircleDiagnostics& d) {
  nlohmann::json terms = nlohmann::json::array();
  for (const auto& t : d.terms)
    terms.push_back({{"name", t.name}, {"value", t.value}, {"sd", t.sd}, {"unit", t.unit}});
  nlohmann::json j = {{"schema", "whirl.ballbar.circle"},
                      {"schema_version", 1},
                      {"plane", ToString(d.plane)},
                      {"radius_mm", d.radius_mm},
                      {"samples", d.samples},
                      {"span_deg", d.span_deg},
                      {"radius_offset_um", d.radius_offset_um},
                      {"centre_offset_um", {d.centre_offset_1_um, d.centre_offset_2_um}},
                      {"scale_mismatch_um_per_m", d.scale_mismatch_um_per_m},
                      {"squareness_urad", d.squareness_urad},
                      {"cyclic_amplitude_um", {d.cyclic_amplitude_1_um, d.cyclic_amplitude_2_um}},
                      {"cyclic_phase_deg", {d.cyclic_phase_1_deg, d.cyclic_phase_2_deg}},
                      {"residual_rms_um", d.residual_rms_um},
                      {"residual_max_um", d.residual_max_um},
                      {"circular_deviation_um", d.circular_deviation_um},
                      {"terms", terms}};
  if (d.plane == Plane::kXZ) j["parallelism_urad"] = d.parallelism_urad;
  return j;
}

}  // namespace whirl::ballbar
