#pragma once
// Subcommand registry: each app/<name>.cc registers itself with DGMM_REGISTER_COMMAND, so adding a
// subcommand never touches main.cc.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace dgmm::app {

// Adds a subcommand (with its options and callback) to the top-level app.
using CommandSetup = std::function<void(CLI::App& root)>;

struct CommandRegistration {
  std::string name;
  CommandSetup setup;
};

std::vector<CommandRegistration>& CommandRegistry();

struct CommandRegistrar {
  CommandRegistrar(std::string name, CommandSetup setup);
};

// True when stderr is a terminal: long work shows progress only then.
bool ShowProgress();

// Prints "\r<label> <done>/<total>" to stderr when ShowProgress(); a final newline when done == total.
void ReportProgress(const std::string& label, long long done, long long total);

}  // namespace dgmm::app

#define DGMM_CONCAT_INNER(a, b) a##b
#define DGMM_CONCAT(a, b) DGMM_CONCAT_INNER(a, b)
// DGMM_REGISTER_COMMAND("fit", SetupFit); at namespace scope in app/fit.cc.
#define DGMM_REGISTER_COMMAND(name, setup) \
  static ::dgmm::app::CommandRegistrar DGMM_CONCAT(dgmm_registrar_, __LINE__)(name, setup)
