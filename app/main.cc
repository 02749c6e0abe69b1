// The `dgmm` command: parses arguments with CLI11 and dispatches to the registered subcommands.
// User-input problems arrive as exceptions and are printed as one line with a non-zero exit.
#include <algorithm>
#include <csignal>
#include <cstdio>
#include <exception>
#include <iostream>
#include <string>

#include "app/command.h"
#include "util/error.h"

int main(int argc, char** argv) {
  // A file-size limit (ulimit -f) becomes a write error with a message, not a SIGXFSZ kill.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App root{"dgmm: Dynamic Gaussian Mixture motion models for legged robots"};
  root.require_subcommand(1);
  // Options of the top level are also accepted after the subcommand (`dgmm cv set.h5 --quiet`).
  root.fallthrough();
  bool quiet = false;
  root.add_flag("--quiet", quiet,
                "no progress, stage lines or warnings on stderr (errors are still printed)");
  root.parse_complete_callback([&quiet] { dgmm::app::SetQuiet(quiet); });
  auto& registry = dgmm::app::CommandRegistry();
  std::sort(registry.begin(), registry.end(),
            [](const auto& a, const auto& b) { return a.name < b.name; });
  for (const auto& command : registry) command.setup(root);
  // After the subcommands: CLI11 copies the flag into subcommands created later.
  root.set_help_all_flag("--help-all", "Help for every subcommand");
  // An unknown first word is an error even with --help, which CLI11 would answer with the main
  // help and exit 0 (`dgmm tnue --help` must not look like success).
  // (The top level has only flags, so the first word without a dash is the command.)
  char** word = std::find_if(argv + 1, argv + argc, [](const char* a) { return a[0] != '-'; });
  if (word != argv + argc &&
      root.get_subcommands([word](CLI::App* sub) { return sub->check_name(*word); }).empty()) {
    std::cerr << "dgmm: error: unknown command '" << std::string(*word).substr(0, 80) << "'"
              << dgmm::app::DidYouMean(*word, root) << " (see dgmm --help)\n";
    return 2;
  }
  try {
    root.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return root.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return root.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return root.exit(e);
  } catch (const CLI::ParseError& e) {
    // One line, like every other user error (CLI11's own exit() adds a second line).
    std::cerr << "dgmm: error: " << e.what() << " (see dgmm --help)\n";
    return e.get_exit_code() != 0 ? e.get_exit_code() : 2;
  } catch (const dgmm::InputError& e) {
    std::cerr << "dgmm: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "dgmm: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
