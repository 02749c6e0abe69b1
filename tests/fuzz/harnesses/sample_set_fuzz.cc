// libFuzzer harness: the sample set reader (lib/io/sample_set_io.h, SampleSetReader) on any
// bytes. InputError is the expected outcome for a corrupt file.
#include "io/sample_set_io.h"
#include "io/sample_stream.h"

#include "fuzz_util.h"
#include "util/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = dgmm::fuzz::WriteInput(data, size, ".h5");
  try {
    dgmm::SampleSetReader reader(path, 1000);  // small chunks: the streaming path
    dgmm::SampleSet chunk;
    while (reader.Next(&chunk)) {
    }
  } catch (const dgmm::InputError&) {
  }
  try {
    dgmm::ReadSampleSet(path);  // one chunk: the whole-set path
  } catch (const dgmm::InputError&) {
  }
  return 0;
}
