// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterPredict(CLI::App& app) {
  auto* sub = app.add_subcommand("predict", "(being built)");
  sub->callback([] { throw InputError("'predict' is not built yet"); });
}
}  // namespace whirl::cli
