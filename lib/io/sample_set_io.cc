#include "io/sample_set_io.h"

#include <climits>

#include "io/hdf5_util.h"
#include "io/sample_stream.h"
#include "util/error.h"

namespace dgmm {

void WriteSampleSet(const SampleSet& set, const std::string& path) {
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError(path, "", e);
  SampleSetWriter writer(path, set);
  // Written in slices so that the HDF5 conversion buffers stay small.
  constexpr int kSlice = 1 << 16;
  for (int start = 0; start < set.size(); start += kSlice) {
    std::vector<int> rows;
    for (int i = start; i < std::min(set.size(), start + kSlice); ++i) rows.push_back(i);
    writer.Append(set.size() <= kSlice ? set : set.Subset(rows));
  }
  writer.Commit();
}

SampleSet ReadSampleSet(const std::string& path) {
  SampleSetReader reader(path, INT_MAX);  // one chunk: the whole set
  SampleSet set = reader.header();
  if (!reader.Next(&set)) throw MakeInputError(path, "x", "no samples");
  return set;
}

std::string DgmmFileKind(const std::string& path) {
  h5::File file = h5::OpenFile(path);
  return h5::ReadFormat(file.get(), path);
}

}  // namespace dgmm
