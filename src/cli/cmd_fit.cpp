// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterFit(CLI::App& app) {
  auto* sub = app.add_subcommand("fit", "(being built)");
  sub->callback([] { throw InputError("'fit' is not built yet"); });
}
}  // namespace whirl::cli
