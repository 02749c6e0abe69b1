// libFuzzer harness: the model reader (lib/io/model_io.h) on any bytes, then a density of the
// model read (a model that passes the reader must be usable). InputError is expected.
#include "io/model_io.h"

#include "fuzz_util.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dgmm::fuzz::WriteInput(data, size, ".h5");
  try {
    const dgmm::MotionModel model = dgmm::ReadModel(path);
    for (const auto& [id, mixture] : model.mixtures) {
      (void)mixture.LogDensity(Eigen::VectorXd::Zero(mixture.dim()));
    }
  } catch (const dgmm::InputError&) {
  }
  return 0;
}
