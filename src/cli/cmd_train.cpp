// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterTrain(CLI::App& app) {
  auto* sub = app.add_subcommand("train", "(being built)");
  sub->callback([] { throw InputError("'train' is not built yet"); });
}
}  // namespace whirl::cli
