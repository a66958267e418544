// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterCompare(CLI::App& app) {
  auto* sub = app.add_subcommand("compare", "(being built)");
  sub->callback([] { throw InputError("'compare' is not built yet"); });
}
}  // namespace whirl::cli
