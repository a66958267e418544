// libFuzzer harness: the ball-bar loaders (ballbar/drift.h ReadReadings, ReadPivots;
// ballbar/circle.h ReadCircleTrace), each given the same input. Bad input must be an InputError;
// any other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
// What loads must make sense too: readings with the shipped pivots (datasets/ballbar/pivots.json)
// give finite drifts and SD43900 values, a trace gives a finite circle fit, loaded pivots give a
// finite drift of a small synthetic reading set; a non-finite number aborts (a finding).
#include "ballbar/circle.h"
#include "ballbar/drift.h"
#include "core/error.h"
#include "fuzz_file.h"

namespace {

using namespace whirl::ballbar;
using whirl::fuzz::RequireFinite;

// datasets/ballbar/pivots.json, rounded: the pivots the shipped readings were taken with.
PivotCentres ShippedPivots() {
  PivotCentres p;
  p[0] = {192.99, 140.09, 63.53};
  p[1] = {404.82, 141.32, 64.00};
  p[2] = {301.96, 317.57, 62.52};
  return p;
}

void CheckDrift(const Readings& readings, const PivotCentres& pivots) {
  try {
    const DriftResult r = ComputeDrift(readings, pivots);
    for (const DriftBlock& b : r.blocks)
      for (int k = 0; k < 3; ++k) {
        RequireFinite(b.drift_um(k));
        RequireFinite(b.drift_sd_um(k));
      }
    for (int k = 0; k < 3; ++k) RequireFinite(r.sd43900_mm(k));
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    const CircleTrace trace = ReadCircleTrace(path);
    try {
      const CircleDiagnostics d = FitCircle(trace, CircleOptions{});
      RequireFinite(d.residual_rms_um);
      RequireFinite(d.circular_deviation_um);
      for (const Term& t : d.terms) RequireFinite(t.value);
    } catch (const whirl::InputError& e) {
    whirl::fuzz::Refused(e);
    }
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  try {
    const PivotCentres pivots = ReadPivots(path);
    // Two palindromic blocks 30 min apart around a ball near the pivots' centroid.
    Readings r;
    r.source = "synthetic";
    const double lengths[2][3] = {{150.0, 150.5, 149.5}, {150.002, 150.501, 149.499}};
    for (int b = 0; b < 2; ++b)
      for (int pivot : {1, 2, 3, 3, 2, 1})
        r.rows.push_back({30.0 * b, pivot, lengths[b][pivot - 1], std::nullopt, 0});
    CheckDrift(r, pivots);
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  try {
    CheckDrift(ReadReadings(path), ShippedPivots());
  } catch (const whirl::InputError& e) {
  whirl::fuzz::Refused(e);
  }
  return 0;
}
