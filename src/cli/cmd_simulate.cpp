// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterSimulate(CLI::App& app) {
  auto* sub = app.add_subcommand("simulate", "(being built)");
  sub->callback([] { throw InputError("'simulate' is not built yet"); });
}
}  // namespace whirl::cli
