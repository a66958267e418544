// libFuzzer harness: the worktable-surface loaders (surface/points.h ReadSurfacePoints,
// ReadPositions; surface/surface.h ReadSurfaceFile; surface/per_point.h ReadPointManifest), each
// given the same input. Bad input must be an InputError; any other exception, crash, hang, leak or
// sanitizer report is a bug (tests/fuzz/README.md). Beyond that, what loads must make sense:
// a surface file evaluates to finite numbers over its measured rectangle and gives a finite 840D
// line; points that fit give a surface whose file reads back (what 'surface fit' writes, 'surface
// predict' reads). A non-finite number or a refused round trip aborts (a finding).
#include <utility>

#include "core/error.h"
#include "core/json_file.h"
#include "fuzz_file.h"
#include "surface/line840d.h"
#include "surface/per_point.h"
#include "surface/points.h"
#include "surface/surface.h"

namespace {

using namespace whirl::surface;
using whirl::fuzz::RequireFinite;

void CheckLoadedSurface(const Surface& s) {
  const Bounds& b = s.bounds;
  const std::pair<double, double> at[] = {
      {b.x_min_mm, b.y_min_mm},
      {b.x_max_mm, b.y_max_mm},
      {b.x_min_mm, b.y_max_mm},
      {0.5 * (b.x_min_mm + b.x_max_mm), 0.5 * (b.y_min_mm + b.y_max_mm)}};
  for (const auto& [x, y] : at) {
    try {
      RequireFinite(s.Evaluate(x, y));
    } catch (const whirl::InputError&) {  // a B-spline outside its grid
    }
  }
  try {
    const AxisLine l = FitAxisLine(s, AxisLineOptions{});
    RequireFinite(l.sd43900_mm);
    RequireFinite(l.sd43910);
    RequireFinite(l.uncorrected_rms_um);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
}

void CheckFittedPoints(const std::vector<SurfacePoint>& points) {
  if (points.size() > 400) return;  // keep each input fast
  for (const Method m : {Method::kCubic, Method::kBspline}) {
    SurfaceFit fit;
    try {
      fit = FitSurface(points, {m, 1});
    } catch (const whirl::InputError& e) {
      whirl::fuzz::Refused(e);
      continue;
    }
    const nlohmann::json j = nlohmann::json::parse(whirl::DumpJson(SurfaceFitToJson(fit)));
    try {
      (void)SurfaceFromJson(j, "fitted surface");
    } catch (const whirl::InputError& e) {
      whirl::fuzz::Refused(e);
      std::abort();  // fit wrote a file that the reader refuses
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    CheckFittedPoints(ReadSurfacePoints(path));
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  try {
    (void)ReadPositions(path);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  try {
    CheckLoadedSurface(ReadSurfaceFile(path));
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  try {
    (void)ReadPointManifest(path, {"time_min", "t1_C", "p_x0_y0_um", "e1_um", "e2_um"});
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
