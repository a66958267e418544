// Placeholder until its owner writes it; replaced before anything lands.
#include "cli/commands.h"
#include "core/error.h"
namespace whirl::cli {
void RegisterLeadReport(CLI::App& app) {
  auto* sub = app.add_subcommand("lead-report", "(being built)");
  sub->callback([] { throw InputError("'lead-report' is not built yet"); });
}
}  // namespace whirl::cli
