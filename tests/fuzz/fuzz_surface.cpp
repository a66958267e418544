// libFuzzer harness: the worktable-surface loaders (surface/points.h ReadSurfacePoints,
// ReadPositions; surface/surface.h ReadSurfaceFile, plus a prediction when a surface loads), each
// given the same input. Bad input must be an InputError; any other exception, crash, hang, leak or
// sanitizer report is a bug (tests/fuzz/README.md).
#include "core/error.h"
#include "fuzz_file.h"
#include "surface/points.h"
#include "surface/surface.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    (void)whirl::surface::ReadSurfacePoints(path);
  } catch (const whirl::InputError&) {
  }
  try {
    (void)whirl::surface::ReadPositions(path);
  } catch (const whirl::InputError&) {
  }
  try {
    const whirl::surface::Surface s = whirl::surface::ReadSurfaceFile(path);
    (void)s.Evaluate(0.0, 0.0);
  } catch (const whirl::InputError&) {
  }
  return 0;
}
