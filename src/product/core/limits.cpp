#include "core/limits.h"

#include <cmath>

#include "core/csv.h"
#include "core/error.h"

namespace whirl {
namespace {

constexpr Range kInputLimits[ProcessInputs::kCount] = {
    {kMinHardnessHrc, kMaxHardnessHrc, false, "HRC"},
    {0, kMaxDiameterMm, true, "mm"},
    {0, kMaxPitchMm, true, "mm"},
    {0, kMaxRacewayRadiusMm, true, "mm"},
    {0, kMaxCuttingSpeedMMin, true, "m/min"}};
constexpr Range kTargetLimits[Features::kCount] = {{0, kMaxElongationUm, false, "um"},
                                                   {0, kMaxSettleTimeS, false, "s"}};

}  // namespace

bool Range::Contains(double x) const {
  return (min_open ? x > min : x >= min) && x <= max;  // false for NaN
}

std::string Range::Text() const {
  std::string s =
      std::string(min_open ? "(" : "[") + FormatNumber(min) + ", " + FormatNumber(max) + "]";
  if (*unit) s += std::string(" ") + unit;
  return s;
}

void CheckRange(double x, const Range& range, const std::string& field, const std::string& what) {
  if (range.Contains(x)) return;
  throw InputError(what + ": " + field + " = " + FormatNumber(x) +
                   " breaks the rule: must lie in " + range.Text() +
                   (*range.note ? std::string(" (") + range.note + ")" : std::string()));
}

void CheckProcessInputs(const ProcessInputs& inputs, const std::string& what) {
  const auto a = inputs.ToArray();
  for (int i = 0; i < ProcessInputs::kCount; ++i)
    CheckRange(a[i], kInputLimits[i], kInputColumns[i], what);
}

void CheckFeatures(const Features& features, const std::string& what) {
  const auto a = features.ToArray();
  for (int k = 0; k < Features::kCount; ++k)
    CheckRange(a[k], kTargetLimits[k], kTargetColumns[k], what);
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
    s += std::string(i ? ", " : " ") + kInputColumns[i] + " " + kInputLimits[i].Text();
  for (int k = 0; k < Features::kCount; ++k)
    s += std::string(", ") + kTargetColumns[k] + " " + kTargetLimits[k].Text();
  return s + ".";
}

}  // namespace whirl
