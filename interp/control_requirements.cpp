#include "interp/control_requirements.h"

#include <algorithm>
#include <cmath>

#include "core/numbers.h"

namespace whirl::interp {

ControlRequirement MakeRequirement(const std::string& datum, const std::string& axis,
                                   RequirementRule rule, RequirementMerge merge, double value,
                                   int decimals, const std::string& use) {
  ControlRequirement r;
  r.datum = datum;
  r.axis = axis;
  r.rule = rule;
  r.merge = merge;
  r.value = value;
  r.decimals = decimals;
  r.uses = {use};
  return r;
}

std::string ToString(const ControlRequirement& r) {
  std::string s = r.datum + (r.axis.empty() ? "" : " on axis " + r.axis);
  if (r.rule == RequirementRule::kAtLeast) {
    s += " >= " + FormatFixed(r.value, r.decimals);
  } else {
    const long mask = std::lround(r.value);
    std::vector<std::string> bits;
    for (int b = 0; b < 31; ++b)
      if (mask & (1L << b)) bits.push_back(std::to_string(b));
    std::string list;
    for (std::size_t i = 0; i < bits.size(); ++i)
      list += (i == 0 ? "" : i + 1 == bits.size() ? " and " : ", ") + bits[i];
    s += std::string(bits.size() == 1 ? ": bit " : ": bits ") + list + " set" +
         (bits.size() > 1 ? " (= " + std::to_string(mask) + ")" : "");
  }
  for (std::size_t i = 0; i < r.uses.size(); ++i) s += (i ? "; " : ": ") + r.uses[i];
  if (!std::isnan(r.stated)) s += " (profile: " + FormatNumber(r.stated) + ")";
  return s;
}

std::vector<ControlRequirement> MergeRequirements(const std::vector<ControlRequirement>& a,
                                                  const std::vector<ControlRequirement>& b) {
  std::vector<ControlRequirement> out = a;
  for (const ControlRequirement& r : b) {
    auto same = std::find_if(out.begin(), out.end(), [&](const ControlRequirement& x) {
      return x.datum == r.datum && x.axis == r.axis;
    });
    if (same == out.end()) {
      out.push_back(r);
      continue;
    }
    switch (same->merge) {
      case RequirementMerge::kMax:
        same->value = std::max(same->value, r.value);
        break;
      case RequirementMerge::kSum:
        same->value += r.value;
        break;
      case RequirementMerge::kUnion:
        same->value = static_cast<double>(std::lround(same->value) | std::lround(r.value));
        break;
    }
    same->decimals = std::max(same->decimals, r.decimals);
    if (std::isnan(same->stated)) same->stated = r.stated;
    same->uses.insert(same->uses.end(), r.uses.begin(), r.uses.end());
  }
  return out;
}

}  // namespace whirl::interp
