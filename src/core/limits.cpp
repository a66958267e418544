#include "core/limits.h"

#include <cmath>

#include "core/csv.h"
#include "core/error.h"

namespace whirl {
namespace {

struct Limit {
  double min, max;
  bool min_open;  // (min, max] instead of [min, max]
  const char* unit;
};

constexpr Limit kInputLimits[ProcessInputs::kCount] = {
    {kMinHardnessHrc, kMaxHardnessHrc, false, "HRC"},
    {0, kMaxDiameterMm, true, "mm"},
    {0, kMaxPitchMm, true, "mm"},
    {0, kMaxRacewayRadiusMm, true, "mm"},
    {0, kMaxCuttingSpeedMMin, true, "m/min"}};
constexpr Limit kTargetLimits[Features::kCount] = {{0, kMaxElongationUm, false, "um"},
                                                   {0, kMaxSettleTimeS, false, "s"}};

std::string RangeText(const Limit& l) {
  return std::string(l.min_open ? "(" : "[") + FormatNumber(l.min) + ", " + FormatNumber(l.max) +
         "] " + l.unit;
}

void Check(double x, const Limit& l, const char* field, const std::string& what) {
  const bool above_min = l.min_open ? x > l.min : x >= l.min;
  if (above_min && x <= l.max) return;  // false for NaN
  throw InputError(what + ": " + field + " = " + FormatNumber(x) +
                   " breaks the rule: must lie in " + RangeText(l) + " (physical limit)");
}

}  // namespace

void CheckProcessInputs(const ProcessInputs& inputs, const std::string& what) {
  const auto a = inputs.ToArray();
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    Check(a[i], kInputLimits[i], kInputColumns[i], what);
}

void CheckFeatures(const Features& features, const std::string& what) {
  const auto a = features.ToArray();
  for (int k = 0; k < Features::kCount; ++k) Check(a[k], kTargetLimits[k], kTargetColumns[k], what);
}

void CheckPlanFeatures(const Features& features, const std::string& what) {
  CheckFeatures(features, what);
  if (!(features.settle_time_s >= kMinPlanSettleTimeS))
    throw InputError(what + ": settle_time_s = " + FormatNumber(features.settle_time_s) +
                     " breaks the rule: at least " + FormatNumber(kMinPlanSettleTimeS) + " s");
}

std::string ProcessLimitsHelp() {
  std::string s = "Physical limits (an error outside):";
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    s += std::string(i ? ", " : " ") + kInputColumns[i] + " " + RangeText(kInputLimits[i]);
  for (int k = 0; k < Features::kCount; ++k)
    s += std::string(", ") + kTargetColumns[k] + " " + RangeText(kTargetLimits[k]);
  return s + ".";
}

}  // namespace whirl
