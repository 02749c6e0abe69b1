// `dgmm upgrade`: converts a trusted version-1 file (sample set or model) to version 2
// (docs/file-format.md). Every other command refuses version 1.
#include <cstdio>
#include <memory>

#include "app/command.h"
#include "io/upgrade.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct UpgradeArgs {
  std::string input, output;
};

void Run(const UpgradeArgs& args) {
  RefuseOutputThatIsAnInput(args.output, {args.input});
  { AtomicFile probe(args.output); }  // fail before reading when the output is unwritable
  const UpgradeSummary s = UpgradeFile(args.input, args.output);
  if (!s.written) {
    std::printf("%s: already format version 2; nothing written\n", args.input.c_str());
    return;
  }
  std::printf("upgraded %s (%s, version %lld) to version 2: wrote %s\n", args.input.c_str(),
              s.kind.c_str(), s.from_version, args.output.c_str());
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<UpgradeArgs>();
  CLI::App* cmd = root.add_subcommand(
      "upgrade",
      "Convert a version-1 sample set or model to format version 2 (fixed-length strings, "
      "checksummed metadata). Only for files you trust: version 1 is read with the old "
      "variable-length string reader. A version-2 input writes nothing.");
  cmd->add_option("input", args->input, "version-1 file (.h5)")->required();
  cmd->add_option("-o,--output", args->output, "version-2 file to write (.h5)")->required();
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("upgrade", Setup);
}  // namespace dgmm::app
