#include "app/command.h"

#include <unistd.h>

#include <cstdio>

namespace dgmm::app {

std::vector<CommandRegistration>& CommandRegistry() {
  static std::vector<CommandRegistration> registry;
  return registry;
}

CommandRegistrar::CommandRegistrar(std::string name, CommandSetup setup) {
  CommandRegistry().push_back({std::move(name), std::move(setup)});
}

bool ShowProgress() { return ::isatty(STDERR_FILENO) == 1; }

void ReportProgress(const std::string& label, long long done, long long total) {
  if (!ShowProgress()) return;
  std::fprintf(stderr, "\r%s %lld/%lld", label.c_str(), done, total);
  if (done >= total) std::fprintf(stderr, "\n");
  std::fflush(stderr);
}

}  // namespace dgmm::app
