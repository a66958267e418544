// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterDataset(CLI::App& app) {
  auto* sub = app.add_subcommand("dataset", "(being built)");
  sub->callback([] { throw InputError("'dataset' is not built yet"); });
}
}  // namespace whirl::cli
