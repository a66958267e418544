// 'whirl crosscheck' and 'whirl export' run in whirl-torch, the executable next to whirl that links
// LibTorch (see torch_main.cpp): whirl itself never loads LibTorch. The forwarders pass every
// argument (including --help) through unchanged and replace this process with whirl-torch, so its
// output and exit code are the command's own.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/error.h"

namespace whirl::cli {
namespace {

std::filesystem::path TorchExecutable() {
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) throw InputError("cannot locate the whirl executable (/proc/self/exe): " + ec.message());
  return self.parent_path() / "whirl-torch";
}

void Forward(const std::string& command, const std::vector<std::string>& args) {
  const std::filesystem::path exe = TorchExecutable();
  if (::access(exe.c_str(), X_OK) != 0) {
    throw InputError("'whirl " + command + "' is not available: " + exe.string() +
                     " does not exist, i.e. whirl was built without LibTorch (install "
                     "libtorch-dev, e.g. with scripts/setup.sh, and rebuild with "
                     "-DWHIRL_WITH_TORCH=ON)");
  }
  std::vector<std::string> storage = {"whirl", command};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  std::fflush(stdout);
  std::fflush(stderr);
  ::execv(exe.c_str(), argv.data());
  throw InputError("cannot run " + exe.string() + ": " + std::strerror(errno));
}

void AddForwarder(CLI::App& app, const std::string& command, const std::string& description) {
  auto* sub = app.add_subcommand(command, description);
  sub->set_help_flag();   // '--help' goes to whirl-torch, which knows the options
  sub->prefix_command();  // every argument after the subcommand is passed through untouched
  sub->callback([sub, command] { Forward(command, sub->remaining()); });
}

}  // namespace

void RegisterTorchForwarders(CLI::App& app) {
  AddForwarder(app, "crosscheck",
               "Check the Eigen network against an independent LibTorch implementation "
               "(forward, Jacobian, objective, gradient, training). Runs whirl-torch.");
  AddForwarder(app, "export",
               "Export a trained model as a TorchScript module (raw inputs -> both outputs, "
               "original units). Runs whirl-torch.");
}

}  // namespace whirl::cli
