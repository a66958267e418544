#include "synthetic/surface.h"

#include <cmath>

#include "core/csv.h"
#include "core/error.h"
#include "core/random.h"

namespace whirl::synthetic {
namespace {

void Require(bool ok, const std::string& field, double value, const std::string& rule) {
  if (!ok)
    throw InputError("synthetic field: " + field + " = " + FormatNumber(value) + ": " + rule);
}

}  // namespace

std::string ToString(SyntheticField f) { return f == SyntheticField::kSmooth ? "smooth" : "bump"; }

SyntheticField ParseSyntheticField(const std::string& s) {
  if (s == "smooth") return SyntheticField::kSmooth;
  if (s == "bump") return SyntheticField::kBump;
  throw InputError("synthetic field '" + s + "' is not 'smooth' or 'bump'");
}

void SyntheticOptions::Validate() const {
  Require(length_x_mm > 0 && length_x_mm <= surface::kMaxCoordinateMm, "length_x_mm", length_x_mm,
          "must be in (0, 100000] mm");
  Require(length_y_mm > 0 && length_y_mm <= surface::kMaxCoordinateMm, "length_y_mm", length_y_mm,
          "must be in (0, 100000] mm");
  Require(nx >= 2 && nx <= static_cast<int>(surface::kMaxGridLines), "nx", nx, "must be in 2..200");
  Require(ny >= 2 && ny <= static_cast<int>(surface::kMaxGridLines), "ny", ny, "must be in 2..200");
  Require(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny) <= surface::kMaxPoints,
          "nx * ny", nx * ny,
          "at most " + std::to_string(surface::kMaxPoints) +
              " points (the limit of a points file, which "
              "surface fit reads)");
  Require(noise_um >= 0 && noise_um <= 10, "noise_um", noise_um, "must be in [0, 10] um");
  Require(bump_um >= 0 && bump_um <= 100, "bump_um", bump_um, "must be in [0, 100] um");
  Require(bump_sigma_fraction >= 0.01 && bump_sigma_fraction <= 1, "bump_sigma_fraction",
          bump_sigma_fraction, "must be in [0.01, 1]");
}

double SyntheticErrorUm(const SyntheticOptions& o, double x_mm, double y_mm) {
  const double s = x_mm / o.length_x_mm, t = y_mm / o.length_y_mm;
  double e =
      10 + 10 * s + 6 * t + 4 * s * s + 3 * s * t - 2 * t * t + 5 * s * s * s + 2 * s * t * t;
  if (o.field == SyntheticField::kBump) {
    const double dx = x_mm - 0.7 * o.length_x_mm, dy = y_mm - 0.35 * o.length_y_mm;
    const double sigma = o.bump_sigma_fraction * o.length_x_mm;
    e += o.bump_um * std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
  }
  return e;
}

std::vector<surface::SurfacePoint> SyntheticPoints(const SyntheticOptions& o) {
  o.Validate();
  Rng rng(o.seed);
  std::vector<surface::SurfacePoint> points;
  for (int i = 0; i < o.ny; ++i)
    for (int j = 0; j < o.nx; ++j) {
      const double x = o.length_x_mm * j / (o.nx - 1), y = o.length_y_mm * i / (o.ny - 1);
      points.push_back({x, y, SyntheticErrorUm(o, x, y) + o.noise_um * rng.Normal()});
    }
  return points;
}

std::vector<std::string> SyntheticProvenance(const SyntheticOptions& o) {
  std::vector<std::string> c{
      " synthetic thermal-error field (no public measurements exist), whirl surface synth",
      " field " + ToString(o.field) +
          ": 10 + 10 s + 6 t + 4 s^2 + 3 s t - 2 t^2 + 5 s^3 + 2 s t^2 um, s = x/" +
          FormatNumber(o.length_x_mm) + ", t = y/" + FormatNumber(o.length_y_mm)};
  if (o.field == SyntheticField::kBump)
    c.push_back(" + " + FormatNumber(o.bump_um) + " um exp(-r^2/(2 sigma^2)) at (" +
                FormatNumber(0.7 * o.length_x_mm) + ", " + FormatNumber(0.35 * o.length_y_mm) +
                ") mm, sigma " + FormatNumber(o.bump_sigma_fraction * o.length_x_mm) + " mm");
  c.push_back(" grid " + std::to_string(o.nx) + " x " + std::to_string(o.ny) + ", noise " +
              FormatNumber(o.noise_um) + " um (normal), seed " + std::to_string(o.seed) +
              " (synthetic/surface.h)");
  return c;
}

}  // namespace whirl::synthetic
