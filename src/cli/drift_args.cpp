#include "cli/drift_args.h"

#include <stdexcept>

#include "cli/common.h"
#include "core/error.h"

namespace whirl::cli {

void AddSelectionOptions(CLI::App* sub, SelectionArgs* s) {
  sub->add_option("--alpha", s->alpha, "significance level of the F test (default 0.05)")
      ->check(NumberIn(1e-6, 0.5));
  sub->add_option("--classes", s->classes,
                  "class count: 'fewest' (Miao et al.: fewest classes with a significant F, "
                  "default), 'margin' (largest (F - F_crit)/F_crit), 'cv' (the count whose "
                  "sensors' MLR has the lowest cross-validated RMSE: leave one run out, or "
                  "forward-chaining blocks of one run) or a number");
  sub->add_option("--max-sensors", s->max_sensors,
                  "at most this many classes = chosen sensors (0: no limit)")
      ->check(NumberIn(0, 64));
}

drift::SelectionOptions ToSelection(const SelectionArgs& a) {
  drift::SelectionOptions o;
  o.alpha = a.alpha;
  o.max_classes = a.max_sensors;
  if (a.classes == "fewest" || a.classes == "margin" || a.classes == "cv") {
    o.rule = drift::ParseClassCountRule(a.classes);
  } else {
    o.rule = drift::ClassCountRule::kFixed;
    try {
      std::size_t used = 0;
      o.fixed_classes = std::stoi(a.classes, &used);
      if (used != a.classes.size()) throw std::invalid_argument(a.classes);
    } catch (const std::exception&) {
      throw InputError("--classes '" + a.classes + "': must be fewest, margin, cv or a number");
    }
  }
  return o;
}

}  // namespace whirl::cli
