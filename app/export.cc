// `dgmm export`: a model file -> JSON for use outside C++ (io/model_io.h, WriteModelJson).
#include <cstdio>
#include <memory>

#include "app/command.h"
#include "util/output_guard.h"
#include "io/model_io.h"
#include "util/atomic_file.h"

namespace dgmm::app {
namespace {

struct ExportArgs {
  std::string model, output;
};

void Run(const ExportArgs& args) {
  RefuseOutputThatIsAnInput(args.output, {args.model});
  { AtomicFile probe(args.output); }  // fail before reading when the output is unwritable
  const MotionModel model = ReadModel(args.model);
  WriteModelJson(model, args.output);
  std::printf("wrote %s (%zu command%s)\n", args.output.c_str(), model.mixtures.size(),
              model.mixtures.size() == 1 ? "" : "s");
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = root.add_subcommand(
      "export",
      "Export a model as JSON: dims and names, per command the weights (normalised and raw), "
      "means and covariances, and the standardisation transform with the components mapped "
      "back to raw units (schema: docs/file-format.md).");
  cmd->add_option("model", args->model, "model file (.h5)")->required();
  cmd->add_option("-o,--output", args->output, "JSON file to write")->required();
  cmd->callback([args] { Run(*args); });
}

}  // namespace
DGMM_REGISTER_COMMAND("export", Setup);
}  // namespace dgmm::app
