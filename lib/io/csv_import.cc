#include "io/csv_import.h"

#include <charconv>
#include <deque>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include "util/error.h"

namespace dgmm {
namespace {

std::string Trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string Line(long long n) { return "line " + std::to_string(n); }

// A cell as echoed in a message: control characters shown as '?', at most 80 characters.
std::string Echo(const std::string& text) {
  constexpr size_t kMaxEcho = 80;
  std::string s = text.substr(0, kMaxEcho);
  for (char& c : s) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (text.size() > kMaxEcho) s += "... (" + std::to_string(text.size()) + " characters)";
  return s;
}

// Lines ending in \n, \r\n or a lone \r (old Mac files are one line per record too).
class LineReader {
 public:
  explicit LineReader(std::istream& in) : in_(in) {}
  bool Next(std::string* line) {
    if (pending_.empty()) {
      std::string raw;
      if (!std::getline(in_, raw)) return false;
      if (!raw.empty() && raw.back() == '\r') raw.pop_back();
      size_t start = 0;
      for (size_t cr = raw.find('\r'); cr != std::string::npos; cr = raw.find('\r', start)) {
        pending_.push_back(raw.substr(start, cr - start));
        start = cr + 1;
      }
      pending_.push_back(raw.substr(start));
    }
    *line = std::move(pending_.front());
    pending_.pop_front();
    return true;
  }

 private:
  std::istream& in_;
  std::deque<std::string> pending_;
};

// Splits one CSV record at commas; fields may be "quoted" (with "" for a quote).
std::vector<std::string> SplitRecord(const std::string& line, const std::string& path,
                                     long long line_no) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false, was_quoted = false;
  for (size_t i = 0; i < line.size(); ++i) {
    char c = line[i];
    if (quoted) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        field += '"';
        ++i;
      } else if (c == '"') {
        quoted = false;
      } else {
        field += c;
      }
    } else if (c == '"' && Trim(field).empty()) {
      quoted = was_quoted = true;
      field.clear();
    } else if (c == ',') {
      fields.push_back(was_quoted ? field : Trim(field));
      field.clear();
      was_quoted = false;
    } else {
      field += c;
    }
  }
  if (quoted) throw MakeInputError(path, Line(line_no), "unterminated quoted field");
  fields.push_back(was_quoted ? field : Trim(field));
  return fields;
}

// The value of one cell; InputError naming the line and column unless finite and numeric.
double ParseNumber(const std::string& cell, const std::string& path, long long line_no,
                   const std::string& column) {
  const std::string field = Line(line_no) + ", column '" + Echo(column) + "'";
  std::string text = Trim(cell);
  if (text.empty()) throw MakeInputError(path, field, "empty value, expected a number");
  const char* begin = text.c_str();
  if (*begin == '+') ++begin;
  double value = 0;
  auto [end, ec] = std::from_chars(begin, text.c_str() + text.size(), value);
  if (ec == std::errc::result_out_of_range && end == text.c_str() + text.size()) {
    // Underflow (1e-400, 0.000...1) reads as 0 or a subnormal; overflow is refused.
    value = std::strtod(begin, nullptr);
    if (std::isinf(value)) {
      throw MakeInputError(path, field,
                           "'" + Echo(text) +
                               "' is infinite as a double (beyond +-1.8e308), expected a finite "
                               "number");
    }
    ec = std::errc();
  }
  if (ec != std::errc() || end != text.c_str() + text.size()) {
    throw MakeInputError(path, field, "'" + Echo(text) + "' is not a number");
  }
  if (std::isnan(value)) throw MakeInputError(path, field, "NaN value, expected a finite number");
  if (std::isinf(value)) {
    throw MakeInputError(path, field, "infinite value, expected a finite number");
  }
  return value;
}

// The names joined with commas, each echoed, cut after about 200 characters.
std::string JoinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) {
    if (s.size() > 200) return s + ", ... (" + std::to_string(names.size()) + " columns)";
    s += (s.empty() ? "" : ", ") + Echo(n);
  }
  return s;
}

// Column index of each name; InputError listing the available columns for unknown names.
std::vector<int> FindColumns(const std::vector<std::string>& wanted,
                             const std::vector<std::string>& header, const std::string& path,
                             std::set<std::string>* used) {
  std::vector<int> indices;
  for (const std::string& name : wanted) {
    int found = -1;
    for (int i = 0; i < static_cast<int>(header.size()); ++i) {
      if (header[i] != name) continue;
      if (found >= 0) {
        throw MakeInputError(path, "column '" + Echo(name) + "'", "appears twice in the header");
      }
      found = i;
    }
    if (found < 0) {
      throw MakeInputError(path, "column '" + Echo(name) + "'",
                           "not found (have: " + JoinNames(header) + ")");
    }
    if (!used->insert(name).second) {
      throw MakeInputError(path, "column '" + name + "'", "selected twice");
    }
    indices.push_back(found);
  }
  return indices;
}

// Mean and population standard deviation per column of y = x || z; scale 1 where sd is 0.
Standardization Standardize(Eigen::MatrixXd* x, Eigen::MatrixXd* z) {
  const Eigen::Index dx = x->cols(), dz = z->cols(), n = x->rows();
  Standardization t;
  t.offset.resize(dx + dz);
  t.scale.resize(dx + dz);
  for (Eigen::Index j = 0; j < dx + dz; ++j) {
    auto column = j < dx ? x->col(j) : z->col(j - dx);
    // In units of the largest magnitude m, so that sums of values near 1e308 cannot overflow.
    const double m = column.cwiseAbs().maxCoeff();
    const double unit = m > 0 ? m : 1.0;
    const Eigen::ArrayXd u = column.array() / unit;
    const double mean_u = u.mean();
    const double sd_u = std::sqrt((u - mean_u).square().sum() / static_cast<double>(n));
    const double scale_u = sd_u > 0 ? sd_u : 1.0 / unit;  // a constant column keeps scale 1
    column = ((u - mean_u) / scale_u).matrix();
    t.offset[j] = mean_u * unit;
    t.scale[j] = scale_u * unit;
  }
  return t;
}

}  // namespace

SampleSet ImportCsv(const std::string& path, const CsvImportOptions& options) {
  if (options.pose_columns.empty()) {
    throw MakeInputError(path, "pose columns", "none chosen (expected at least one)");
  }
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw MakeInputError(path, "", "is a folder, expected a CSV file");
  }
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw MakeInputError(path, "", "file not found");
  }
  std::ifstream in(path);
  if (!in) throw MakeInputError(path, "", "cannot open for reading");

  std::string line;
  long long line_no = 0;
  std::vector<std::string> header;
  LineReader lines(in);
  while (lines.Next(&line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 BOM
    if (Trim(line).empty()) continue;
    header = SplitRecord(line, path, line_no);
    break;
  }
  if (header.empty()) throw MakeInputError(path, "", "empty file (expected a header row)");

  std::set<std::string> used;
  const auto command_idx = FindColumns(options.command_columns, header, path, &used);
  const auto pose_idx = FindColumns(options.pose_columns, header, path, &used);
  const auto terrain_idx = FindColumns(options.terrain_columns, header, path, &used);
  std::vector<int> episode_idx;
  if (!options.episode_column.empty()) {
    episode_idx = FindColumns({options.episode_column}, header, path, &used);
  }

  const int dx = static_cast<int>(pose_idx.size()), dz = static_cast<int>(terrain_idx.size());
  std::vector<double> xs, zs;
  std::vector<int> commands, episodes, steps;
  std::map<std::vector<double>, int> command_ids;
  std::vector<std::vector<double>> command_rows;
  std::vector<std::string> labels;
  std::map<int, int> steps_so_far;
  while (lines.Next(&line)) {
    ++line_no;
    if (Trim(line).empty()) continue;
    const auto fields = SplitRecord(line, path, line_no);
    if (fields.size() != header.size()) {
      throw MakeInputError(path, Line(line_no),
                           std::to_string(fields.size()) + " fields, expected " +
                               std::to_string(header.size()) + " as in the header (ragged row)");
    }
    auto number = [&](int col) { return ParseNumber(fields[col], path, line_no, header[col]); };
    std::vector<double> key;
    std::string label;
    for (int col : command_idx) {
      key.push_back(number(col));
      label += (label.empty() ? "" : ",") + Trim(fields[col]);
    }
    auto [it, inserted] = command_ids.try_emplace(key, static_cast<int>(command_rows.size()));
    if (inserted) {
      command_rows.push_back(key);
      labels.push_back(command_idx.empty() ? "all" : label);
    }
    commands.push_back(it->second);
    for (int col : pose_idx) xs.push_back(number(col));
    for (int col : terrain_idx) zs.push_back(number(col));
    if (!episode_idx.empty()) {
      const double e = number(episode_idx[0]);
      if (e != std::floor(e) || std::abs(e) > 2e9) {
        char shown[32];
        std::snprintf(shown, sizeof shown, "%.6g", e);
        throw MakeInputError(path, Line(line_no) + ", column '" + Echo(header[episode_idx[0]]) + "'",
                             std::string("episode id ") + shown +
                                 ", expected an integer between -2e9 and 2e9");
      }
      episodes.push_back(static_cast<int>(e));
      steps.push_back(steps_so_far[static_cast<int>(e)]++);
    }
  }
  const long long n = static_cast<long long>(commands.size());
  if (n == 0) throw MakeInputError(path, "", "no data rows after the header");

  SampleSet set;
  set.command_dim_names = options.command_columns;
  set.commands.resize(static_cast<Eigen::Index>(command_rows.size()),
                      static_cast<Eigen::Index>(command_idx.size()));
  for (size_t r = 0; r < command_rows.size(); ++r) {
    for (size_t c = 0; c < command_idx.size(); ++c) set.commands(r, c) = command_rows[r][c];
  }
  set.command_labels = labels;
  set.command = Eigen::Map<Eigen::VectorXi>(commands.data(), n);
  using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  set.x = Eigen::Map<RowMatrix>(xs.data(), n, dx);
  set.x_names = options.pose_columns;
  if (dz > 0) {
    set.z = Eigen::Map<RowMatrix>(zs.data(), n, dz);
    set.z_names = options.terrain_columns;
  }
  if (!episodes.empty()) {
    set.episode = Eigen::Map<Eigen::VectorXi>(episodes.data(), n);
    set.step = Eigen::Map<Eigen::VectorXi>(steps.data(), n);
  }
  set.source = options.source;
  set.metadata["imported_from"] = std::filesystem::path(path).filename().string();
  if (options.standardize) set.transform = Standardize(&set.x, &set.z);
  if (std::string e = set.Validate(); !e.empty()) throw MakeInputError(path, "", e);
  return set;
}

}  // namespace dgmm
