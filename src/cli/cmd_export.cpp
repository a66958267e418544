// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterExport(CLI::App& app) {
  auto* sub = app.add_subcommand("export", "(being built)");
  sub->callback([] { throw InputError("'export' is not built yet"); });
}
}  // namespace whirl::cli
