#include "io/csv_reader.h"

#include <charconv>
#include <cmath>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "util/error.h"

namespace dgmm {
namespace {

std::string Trim(const std::string& s) {
  size_t b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? "" : s.substr(b, e - b + 1);
}

std::string Line(long long n) { return "line " + std::to_string(n); }

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

// Splits one record at `delimiter`; fields may be "quoted" (with "" for a quote).
std::vector<std::string> SplitRecord(const std::string& line, char delimiter,
                                     const std::string& path, long long line_no) {
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
    } else if (c == delimiter) {
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

// The names joined with commas, each echoed, cut after about 200 characters.
std::string JoinNames(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) {
    if (s.size() > 200) return s + ", ... (" + std::to_string(names.size()) + " columns)";
    s += (s.empty() ? "" : ", ") + EchoCell(n);
  }
  return s;
}

}  // namespace

std::string EchoCell(const std::string& text) {
  constexpr size_t kMaxEcho = 80;
  std::string s = text.substr(0, kMaxEcho);
  for (char& c : s) {
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
  }
  if (text.size() > kMaxEcho) s += "... (" + std::to_string(text.size()) + " characters)";
  return s;
}

int CsvTable::Column(const std::string& name) const {
  int found = -1;
  for (int i = 0; i < static_cast<int>(header.size()); ++i) {
    if (header[i] != name) continue;
    if (found >= 0) throw MakeInputError(path, "column '" + EchoCell(name) + "'", "appears twice in the header");
    found = i;
  }
  if (found < 0) {
    std::string hint;
    if (header.size() == 1 && header[0].find_first_of(";\t|") != std::string::npos) {
      hint = "; is the file delimited by another character? see --delimiter";
    }
    throw MakeInputError(path, "column '" + EchoCell(name) + "'",
                         "not found (have: " + JoinNames(header) + ")" + hint);
  }
  return found;
}

void CsvTable::CheckFieldCount(const CsvRecord& record) const {
  if (record.fields.size() == header.size()) return;
  throw MakeInputError(path, Line(record.line),
                       std::to_string(record.fields.size()) + " fields, expected " +
                           std::to_string(header.size()) + " as in the header (ragged row)");
}

double CsvTable::Number(const CsvRecord& record, int col) const {
  double value = 0;
  std::string problem;
  if (!ParseFiniteNumber(record.fields.at(col), &value, &problem)) {
    throw MakeInputError(path, Line(record.line) + ", column '" + EchoCell(header[col]) + "'",
                         problem);
  }
  return value;
}

bool CsvTable::IsNumericColumn(int col) const {
  double value = 0;
  std::string problem;
  for (const CsvRecord& r : records) {
    if (col >= static_cast<int>(r.fields.size())) continue;
    const std::string& cell = r.fields[col];
    if (cell.empty() || cell == "nan" || cell == "NaN" || cell == "NAN") continue;
    if (!ParseFiniteNumber(cell, &value, &problem)) return false;
  }
  return true;
}

CsvTable ReadCsv(const std::string& path, char delimiter, bool has_header) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw MakeInputError(path, "", "is a folder, expected a CSV file");
  }
  if (!std::filesystem::is_regular_file(path, ec)) throw MakeInputError(path, "", "file not found");
  std::ifstream in(path);
  if (!in) throw MakeInputError(path, "", "cannot open for reading");
  CsvTable table;
  table.path = path;
  std::string line;
  long long line_no = 0;
  LineReader lines(in);
  while (lines.Next(&line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 BOM
    if (Trim(line).empty()) continue;
    auto fields = SplitRecord(line, delimiter, path, line_no);
    if (table.header.empty() && !has_header) {
      for (size_t i = 1; i <= fields.size(); ++i) table.header.push_back(std::to_string(i));
    }
    if (table.header.empty()) {
      table.header = std::move(fields);
    } else {
      table.records.push_back({line_no, std::move(fields)});
    }
  }
  if (table.header.empty()) {
    throw MakeInputError(path, "",
                         has_header ? "empty file (expected a header row)" : "empty file");
  }
  return table;
}

char ParseDelimiter(const std::string& text) {
  if (text == "," || text == ";" || text == "|" || text == " ") return text[0];
  if (text == "tab" || text == "\\t" || text == "\t") return '\t';
  throw MakeInputError("", "--delimiter",
                       "'" + text + "' is not supported (expected one of: , ; tab | space)");
}

bool ParseFiniteNumber(const std::string& cell, double* value, std::string* problem) {
  const std::string text = Trim(cell);
  if (text.empty()) {
    *problem = "empty value, expected a number";
    return false;
  }
  const char* begin = text.c_str();
  if (*begin == '+') ++begin;
  auto [end, ec] = std::from_chars(begin, text.c_str() + text.size(), *value);
  if (ec == std::errc::result_out_of_range && end == text.c_str() + text.size()) {
    // Underflow (1e-400, 0.000...1) reads as 0 or a subnormal; overflow is refused.
    *value = std::strtod(begin, nullptr);
    if (std::isinf(*value)) {
      *problem = "'" + EchoCell(text) +
                 "' is infinite as a double (beyond +-1.8e308), expected a finite number";
      return false;
    }
    ec = std::errc();
  }
  if (ec != std::errc() || end != text.c_str() + text.size()) {
    *problem = "'" + EchoCell(text) + "' is not a number";
    return false;
  }
  if (std::isnan(*value)) {
    *problem = "NaN value, expected a finite number";
    return false;
  }
  if (std::isinf(*value)) {
    *problem = "infinite value, expected a finite number";
    return false;
  }
  return true;
}

double UnitToSi(const std::string& unit) {
  static const std::map<std::string, double> kUnits = {
      {"m", 1.0},   {"cm", 1e-2},  {"mm", 1e-3},
      {"rad", 1.0}, {"deg", std::numbers::pi / 180.0},
      {"s", 1.0},   {"ms", 1e-3},  {"us", 1e-6}, {"ns", 1e-9}};
  auto it = kUnits.find(unit);
  if (it == kUnits.end()) {
    throw MakeInputError("", "--units",
                         "unknown unit '" + unit + "' (expected m, cm, mm, rad, deg, s, ms, us, ns)");
  }
  return it->second;
}

std::map<std::string, double> ParseUnits(const std::vector<std::string>& items) {
  std::map<std::string, double> units;
  std::map<std::string, std::string> names;  // as given, for the message
  for (const std::string& item : items) {
    const size_t eq = item.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == item.size()) {
      throw MakeInputError("", "--units",
                           "'" + item + "' is not COLUMN=UNIT (e.g. yaw=deg,x=mm; comma-separated)");
    }
    const std::string column = Trim(item.substr(0, eq)), unit = Trim(item.substr(eq + 1));
    const double factor = UnitToSi(unit);
    const auto [it, fresh] = units.try_emplace(column, factor);
    if (!fresh && it->second != factor) {
      throw MakeInputError("", "--units",
                           "column '" + column + "' is given two different units (" +
                               names[column] + " and " + unit + "); give one");
    }
    names[column] = unit;
  }
  return units;
}

void InvalidRows::Handle(const std::string& path, const std::string& message) {
  if (!drop_) throw InputError(message + " (use --drop-invalid to skip such rows)");
  if (count_[path]++ == 0) first_[path] = message;
}

long long InvalidRows::total() const {
  long long n = 0;
  for (const auto& [path, count] : count_) n += count;
  return n;
}

std::vector<std::string> InvalidRows::Report() const {
  std::vector<std::string> lines;
  for (const auto& [path, count] : count_) {
    lines.push_back("dropped " + std::to_string(count) + " invalid row" + (count == 1 ? "" : "s") +
                    " from " + std::filesystem::path(path).filename().string() +
                    " (first: " + first_.at(path) + ")");
  }
  return lines;
}

}  // namespace dgmm
