#pragma once
// A recorded sample set: per sample a command, the change of pose x and optionally the terrain z
// observed before the command. Storage-agnostic (io/ reads and writes it as HDF5 or CSV).
#include <Eigen/Dense>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace dgmm {

// y_raw = offset + scale .* y_std, per dimension of y = x || z.
struct Standardization {
  Eigen::VectorXd offset;
  Eigen::VectorXd scale;
  bool empty() const { return offset.size() == 0; }
};

struct SampleSet {
  // Command table: one row per command; columns named by command_dim_names (may be 0 columns
  // for a single unnamed command). command_labels names each row (e.g. "+0.5,0,-0.5").
  std::vector<std::string> command_dim_names;
  Eigen::MatrixXd commands;                 // C x dc
  std::vector<std::string> command_labels;  // C
  // Per sample: row index into the command table.
  Eigen::VectorXi command;                  // N
  Eigen::MatrixXd x;                        // N x dx, change of pose
  std::vector<std::string> x_names, x_units;
  Eigen::MatrixXd z;                        // N x dz (dz may be 0), terrain before the command
  std::vector<std::string> z_names, z_units;
  // Recording order (both empty or both N): placement/episode id and step within it.
  Eigen::VectorXi episode, step;
  std::string source;                       // e.g. "sim", "real", "csv"
  std::map<std::string, std::string> metadata;
  Standardization transform;                // set when x||z were standardised on import

  int size() const { return static_cast<int>(x.rows()); }
  int pose_dim() const { return static_cast<int>(x.cols()); }
  int terrain_dim() const { return static_cast<int>(z.cols()); }
  int num_commands() const { return static_cast<int>(commands.rows()); }
  bool has_sequence() const { return episode.size() > 0; }
  // y_i = x_i || z_i as a column vector.
  Eigen::VectorXd Joint(int i) const;

  // Empty string when consistent; otherwise one line naming the field and what was expected
  // (sizes, names, command indices in range, finite values, non-empty).
  std::string Validate() const;
  // Samples whose rows are listed, same tables and metadata.
  SampleSet Subset(const std::vector<int>& rows) const;
};

}  // namespace dgmm
