// libFuzzer harness: the ball-bar loaders (ballbar/drift.h ReadReadings, ReadPivots;
// ballbar/circle.h ReadCircleTrace), each given the same input. Bad input must be an InputError;
// any other exception, crash, hang, leak or sanitizer report is a bug (tests/fuzz/README.md).
#include "ballbar/circle.h"
#include "ballbar/drift.h"
#include "core/error.h"
#include "fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path path = whirl::fuzz::FuzzFile(data, size, ".csv");
  try {
    (void)whirl::ballbar::ReadCircleTrace(path);
  } catch (const whirl::InputError&) {
  }
  try {
    (void)whirl::ballbar::ReadPivots(path);
  } catch (const whirl::InputError&) {
  }
  try {
    (void)whirl::ballbar::ReadReadings(path);
  } catch (const whirl::InputError&) {
  }
  return 0;
}
