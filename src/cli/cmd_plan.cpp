// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterPlan(CLI::App& app) {
  auto* sub = app.add_subcommand("plan", "(being built)");
  sub->callback([] { throw InputError("'plan' is not built yet"); });
}
}  // namespace whirl::cli
