// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterCurve(CLI::App& app) {
  auto* sub = app.add_subcommand("curve", "(being built)");
  sub->callback([] { throw InputError("'curve' is not built yet"); });
}
}  // namespace whirl::cli
