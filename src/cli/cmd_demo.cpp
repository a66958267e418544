// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterDemo(CLI::App& app) {
  auto* sub = app.add_subcommand("demo", "(being built)");
  sub->callback([] { throw InputError("'demo' is not built yet"); });
}
}  // namespace whirl::cli
