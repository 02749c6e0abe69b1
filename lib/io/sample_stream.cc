#include "io/sample_stream.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "io/hdf5_util.h"
#include "io/schema.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

std::string Str(long long v) { return std::to_string(v); }

// The header's tables plus no samples.
SampleSet HeaderOnly(const SampleSet& set) {
  SampleSet h = set.Subset({});
  h.x.resize(0, set.pose_dim());
  h.z.resize(0, set.terrain_dim());
  return h;
}

// "<what>: row r, column c is NaN/infinite" for the first non-finite entry, or nothing.
std::optional<std::string> FirstNonFinite(const Eigen::MatrixXd& m, long long first_row,
                                          const char* what) {
  if (m.allFinite()) return std::nullopt;
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    for (Eigen::Index c = 0; c < m.cols(); ++c) {
      if (!std::isfinite(m(r, c))) {
        return std::string(what) + ": sample " + Str(first_row + r) + ", column " + Str(c) +
               " is " + (std::isnan(m(r, c)) ? "NaN" : "infinite");
      }
    }
  }
  return std::nullopt;
}

}  // namespace

// ---------------------------------------------------------------------------------------
struct SampleSetReader::Impl {
  std::string path;
  h5::File file;
  h5::Dataset command, x, z, episode, step;
  SampleSet header;
  long long size = 0;
  long long position = 0;
  int chunk_rows = 0;
};

SampleSetReader::SampleSetReader(const std::string& path, int chunk_rows)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.chunk_rows = std::max(chunk_rows, 1);
  m.file = h5::OpenFile(path);
  m.header = io_internal::ReadSampleSetHeader(m.file.get(), path, &m.size);
  auto open = [&](const char* name) {
    return h5::Exists(m.file.get(), name) ? h5::Dataset(H5Dopen2(m.file.get(), name, H5P_DEFAULT))
                                          : h5::Dataset();
  };
  m.command = open("command");
  m.x = open("x");
  m.z = open("z");
  m.episode = open("episode");
  m.step = open("step");
  if (!m.command.valid() || !m.x.valid()) {
    throw MakeInputError(path, "x", "cannot open (corrupt file?)");
  }
}

SampleSetReader::~SampleSetReader() = default;

const SampleSet& SampleSetReader::header() const { return impl_->header; }

long long SampleSetReader::size() const { return impl_->size; }

bool SampleSetReader::Next(SampleSet* chunk) {
  Impl& m = *impl_;
  if (m.position >= m.size) return false;
  const long long n = std::min<long long>(m.chunk_rows, m.size - m.position);
  const long long dx = m.header.pose_dim(), dz = m.header.terrain_dim();
  const long long commands = m.header.num_commands();
  const hsize_t start = static_cast<hsize_t>(m.position);
  const hsize_t rows = static_cast<hsize_t>(n);

  *chunk = m.header;  // the tables (small); per-sample arrays are filled below
  chunk->command.resize(n);
  h5::ReadRows(m.command.get(), false, start, rows, 0, chunk->command.data(), m.path, "command");
  for (long long i = 0; i < n; ++i) {
    if (chunk->command[i] < 0 || chunk->command[i] >= commands) {
      throw MakeInputError(m.path, "command",
                           "sample " + Str(m.position + i) + " has command index " +
                               Str(chunk->command[i]) + ", expected 0.." + Str(commands - 1));
    }
  }
  RowMatrix buffer(n, dx);
  h5::ReadRows(m.x.get(), true, start, rows, dx, buffer.data(), m.path, "x");
  chunk->x = buffer;
  if (auto e = FirstNonFinite(chunk->x, m.position, "x")) throw MakeInputError(m.path, "", *e);
  if (dz > 0) {
    buffer.resize(n, dz);
    h5::ReadRows(m.z.get(), true, start, rows, dz, buffer.data(), m.path, "z");
    chunk->z = buffer;
    if (auto e = FirstNonFinite(chunk->z, m.position, "z")) throw MakeInputError(m.path, "", *e);
  } else {
    chunk->z.resize(0, 0);
  }
  if (m.episode.valid()) {
    chunk->episode.resize(n);
    chunk->step.resize(n);
    h5::ReadRows(m.episode.get(), false, start, rows, 0, chunk->episode.data(), m.path, "episode");
    h5::ReadRows(m.step.get(), false, start, rows, 0, chunk->step.data(), m.path, "step");
  } else {
    chunk->episode.resize(0);
    chunk->step.resize(0);
  }
  m.position += n;
  return true;
}

// ---------------------------------------------------------------------------------------
struct SampleSetWriter::Impl {
  std::string path;
  std::optional<AtomicFile> output;
  h5::File file;
  SampleSet header;
  std::optional<h5::RowAppender> command, x, z, episode, step;
  long long size = 0;
  bool sequence_decided = false;
};

SampleSetWriter::SampleSetWriter(const std::string& path, const SampleSet& header)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.header = HeaderOnly(header);
  // The header must be a valid set once it has a sample: check it with one zero sample.
  SampleSet probe = m.header;
  probe.command = Eigen::VectorXi::Zero(1);
  probe.x = Eigen::MatrixXd::Zero(1, header.pose_dim());
  if (header.terrain_dim() > 0) probe.z = Eigen::MatrixXd::Zero(1, header.terrain_dim());
  if (std::string e = probe.Validate(); !e.empty()) throw MakeInputError(path, "", e);

  h5::Init();
  m.output.emplace(path);
  m.file = h5::CreateFile(m.output->temp_path().string(), path);
  const hid_t f = m.file.get();
  const hsize_t chunk = io_internal::kChunkRows;
  m.command.emplace(f, "command", false, 0, chunk, path);
  m.x.emplace(f, "x", true, header.pose_dim(), chunk, path);
  if (header.terrain_dim() > 0) m.z.emplace(f, "z", true, header.terrain_dim(), chunk, path);
  io_internal::WriteSampleSetHeader(f, m.header, path);
}

SampleSetWriter::~SampleSetWriter() {
  if (!impl_) return;
  impl_->file.reset();  // close before AtomicFile removes the temporary file
}

long long SampleSetWriter::size() const { return impl_->size; }

void SampleSetWriter::Append(const SampleSet& chunk) {
  Impl& m = *impl_;
  if (!m.file.valid()) throw MakeInputError(m.path, "", "writer already committed");
  const long long n = chunk.size();
  if (chunk.pose_dim() != m.header.pose_dim() || chunk.terrain_dim() != m.header.terrain_dim()) {
    throw MakeInputError(m.path, "x",
                         "chunk has " + Str(chunk.pose_dim()) + "+" + Str(chunk.terrain_dim()) +
                             " dimensions, expected " + Str(m.header.pose_dim()) + "+" +
                             Str(m.header.terrain_dim()));
  }
  if (chunk.command.size() != n || (chunk.terrain_dim() > 0 && chunk.z.rows() != n)) {
    throw MakeInputError(m.path, "command", "one command (and z row) per sample expected");
  }
  if (n == 0) return;
  if (!m.sequence_decided) {
    m.sequence_decided = true;
    if (chunk.has_sequence()) {
      const hsize_t rows = io_internal::kChunkRows;
      m.episode.emplace(m.file.get(), "episode", false, 0, rows, m.path);
      m.step.emplace(m.file.get(), "step", false, 0, rows, m.path);
    }
  }
  if (chunk.has_sequence() != m.episode.has_value() ||
      (chunk.has_sequence() && (chunk.episode.size() != n || chunk.step.size() != n))) {
    throw MakeInputError(m.path, "episode", "every sample needs an episode and step, or none does");
  }
  const long long commands = m.header.num_commands();
  for (long long i = 0; i < n; ++i) {
    if (chunk.command[i] < 0 || chunk.command[i] >= commands) {
      throw MakeInputError(m.path, "command",
                           "sample " + Str(m.size + i) + " has command index " +
                               Str(chunk.command[i]) + ", expected 0.." + Str(commands - 1));
    }
  }
  if (auto e = FirstNonFinite(chunk.x, m.size, "x")) throw MakeInputError(m.path, "", *e);
  if (auto e = FirstNonFinite(chunk.z, m.size, "z")) throw MakeInputError(m.path, "", *e);

  m.command->Append(chunk.command.data(), n);
  RowMatrix rows = chunk.x;
  m.x->Append(rows.data(), n);
  if (m.z) {
    rows = chunk.z;
    m.z->Append(rows.data(), n);
  }
  if (m.episode) {
    m.episode->Append(chunk.episode.data(), n);
    m.step->Append(chunk.step.data(), n);
  }
  m.size += n;
}

void SampleSetWriter::Commit() {
  Impl& m = *impl_;
  if (!m.file.valid()) throw MakeInputError(m.path, "", "writer already committed");
  if (m.size == 0) throw MakeInputError(m.path, "x", "no samples (expected at least one)");
  m.command.reset();
  m.x.reset();
  m.z.reset();
  m.episode.reset();
  m.step.reset();
  if (H5Fflush(m.file.get(), H5F_SCOPE_GLOBAL) < 0) {
    throw MakeInputError(m.path, "", "cannot write (disk full?)");
  }
  m.file.reset();
  m.output->Commit();
}

}  // namespace dgmm
