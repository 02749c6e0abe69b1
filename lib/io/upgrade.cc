#include "io/upgrade.h"

#include "io/hdf5_util.h"
#include "io/model_io.h"
#include "io/sample_stream.h"
#include "util/error.h"

namespace dgmm {

UpgradeSummary UpgradeFile(const std::string& input, const std::string& output) {
  UpgradeSummary summary;
  h5::TrustedLegacyRead legacy;  // the user vouches for the input (dgmm upgrade's contract)
  {
    h5::File file = h5::OpenFile(input);
    summary.from_version = h5::ReadFormatVersion(file.get(), input);
    summary.kind = h5::ReadFormat(file.get(), input);
  }
  if (summary.from_version == h5::kFormatVersion) return summary;
  if (summary.kind == "model") {
    WriteModel(ReadModel(input), output);
  } else {
    SampleSetReader reader(input);
    SampleSetWriter writer(output, reader.header());
    SampleSet chunk;
    while (reader.Next(&chunk)) writer.Append(chunk);
    summary.samples = writer.size();
    writer.Commit();
  }
  summary.written = true;
  return summary;
}

}  // namespace dgmm
