// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterCrosscheck(CLI::App& app) {
  auto* sub = app.add_subcommand("crosscheck", "(being built)");
  sub->callback([] { throw InputError("'crosscheck' is not built yet"); });
}
}  // namespace whirl::cli
