// libFuzzer harness: the simulation config JSON reader (lib/sim/sim_config.h) on any text.
#include "sim/sim_config.h"

#include <string>

#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    dgmm::sim::SimConfigFromJson(text, "fuzz.json");
  } catch (const dgmm::InputError&) {
  }
  return 0;
}
