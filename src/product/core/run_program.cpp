#include "core/run_program.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <stdexcept>

namespace whirl {

int RunProgram(const std::vector<std::string>& argv, const std::filesystem::path& cwd,
               const std::filesystem::path& log_path) {
  if (argv.empty() || argv[0].empty()) throw std::invalid_argument("RunProgram: empty argv");
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const std::string cwd_s = cwd.string();
  const std::string log_s = log_path.empty() ? std::string("/dev/null") : log_path.string();

  const pid_t pid = fork();
  if (pid < 0) return 127;
  if (pid == 0) {  // child: only async-signal-safe calls until exec
    const int in = open("/dev/null", O_RDONLY);
    if (in >= 0) dup2(in, STDIN_FILENO);
    // The log first: a relative log_path is relative to the caller's directory, not to cwd.
    const int out = open(log_s.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
    if (out < 0) _exit(127);
    if (!cwd_s.empty() && chdir(cwd_s.c_str()) != 0) _exit(127);
    dup2(out, STDOUT_FILENO);
    dup2(out, STDERR_FILENO);
    execvp(args[0], args.data());
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0) {
    if (errno != EINTR) return 127;
  }
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return 127;
}

bool ProgramSucceeds(const std::vector<std::string>& argv) { return RunProgram(argv) == 0; }

}  // namespace whirl
