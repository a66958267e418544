// whirl-torch: the LibTorch half of whirl ('crosscheck' and 'export'). It is a separate executable
// so that no other whirl command loads LibTorch (about 290 shared libraries and ~0.7 s of start-up
// on these machines); users run it through 'whirl crosscheck' / 'whirl export'.
#include "cli/commands.h"
#include "cli/common.h"

int main(int argc, char** argv) {
  CLI::App app{"whirl (LibTorch part): cross-check of the Eigen network and TorchScript export."};
  app.name("whirl");
  app.require_subcommand(1);
  app.set_version_flag("--version", "whirl 0.1.0");
  whirl::cli::RegisterCrosscheck(app);
  whirl::cli::RegisterExport(app);
  return whirl::cli::RunApp(app, argc, argv);
}
