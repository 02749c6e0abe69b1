#pragma once
// Internal to dgmm::io: the parts of the file schema (docs/file-format.md) shared by sample sets
// and models, and the sample-set header (everything but the per-sample arrays).
#include <hdf5.h>

#include <map>
#include <string>

#include "core/sample_set.h"

namespace dgmm::io_internal {

// Rows per HDF5 chunk of the per-sample datasets (x: 16384 x dx doubles, ~1 MB at dx = 8).
inline constexpr int kChunkRows = 16384;

// /transform/offset and /transform/scale (length d), only when the transform is not empty.
void WriteTransform(hid_t file, const Standardization& transform, const std::string& path);
// Empty when there is no /transform group; InputError unless both have `expected_dim` entries
// and scales are finite and > 0.
Standardization ReadTransform(hid_t file, long long expected_dim, const std::string& path);

// /metadata: one string attribute per key.
void WriteMetadata(hid_t file, const std::map<std::string, std::string>& metadata,
                   const std::string& path);
std::map<std::string, std::string> ReadMetadata(hid_t file, const std::string& path);

// The command table under `group`: values (C x dc, row-major) with attribute dim_names, and
// labels (C strings) when given.
void WriteCommandTable(hid_t group, const Eigen::MatrixXd& values,
                       const std::vector<std::string>& dim_names,
                       const std::vector<std::string>& labels, const std::string& path);
// Fills values/dim_names/labels from `group`; InputError on wrong shapes.
void ReadCommandTable(hid_t group, const std::string& group_name, Eigen::MatrixXd* values,
                      std::vector<std::string>* dim_names, std::vector<std::string>* labels,
                      const std::string& path);

// Root attributes, command table, names/units, transform and metadata of a sample set.
void WriteSampleSetHeader(hid_t file, const SampleSet& header, const std::string& path);
// The header (per-sample arrays empty) and the number of samples in the file; checks that all
// per-sample datasets have matching shapes.
SampleSet ReadSampleSetHeader(hid_t file, const std::string& path, long long* num_samples);

}  // namespace dgmm::io_internal
