// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterEvaluate(CLI::App& app) {
  auto* sub = app.add_subcommand("evaluate", "(being built)");
  sub->callback([] { throw InputError("'evaluate' is not built yet"); });
}
}  // namespace whirl::cli
