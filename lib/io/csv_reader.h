#pragma once
// Reading delimited text files: records with their line numbers, numbers checked cell by cell,
// unit conversion to SI and the invalid-row policy shared by `import` and `import-log`.
#include <map>
#include <string>
#include <vector>

namespace dgmm {

// One data record: its 1-based line in the file and its fields (trimmed unless quoted).
struct CsvRecord {
  long long line = 0;
  std::vector<std::string> fields;
};

// A delimited file: header row and data records (blank lines skipped; records may be ragged,
// see CheckFieldCount).
struct CsvTable {
  std::string path;
  std::vector<std::string> header;
  std::vector<CsvRecord> records;

  // Index of the header column `name`; InputError "<path>: column 'name': not found (have: ...)".
  int Column(const std::string& name) const;
  // InputError "<path>: line L: n fields, expected m ..." unless the record matches the header.
  void CheckFieldCount(const CsvRecord& record) const;
  // True when every non-empty, non-NaN cell of column `col` is a number (else: text labels).
  bool IsNumericColumn(int col) const;
  // The finite number in record's column `col`; InputError naming line and column otherwise.
  double Number(const CsvRecord& record, int col) const;
};

// A cell or column name as echoed in a message: control characters shown as '?', at most 80
// characters, then "... (N characters)".
std::string EchoCell(const std::string& text);

// Reads `path` with fields separated by `delimiter` ("quoted" fields may hold it; "" is a quote).
// Lines may end in \n, \r\n or a lone \r. InputError for a missing/unreadable/empty file, a
// folder, or an unterminated quote. has_header false: every row is data and the columns are
// named by position, "1", "2", ... (from the first row's field count).
CsvTable ReadCsv(const std::string& path, char delimiter = ',', bool has_header = true);

// "," ";" "tab" (or "\t") "|" " " -> the character; InputError naming --delimiter otherwise.
char ParseDelimiter(const std::string& text);

// True and *value when `cell` is a finite number ("+1", "2e-3"); *problem says why not.
bool ParseFiniteNumber(const std::string& cell, double* value, std::string* problem);

// Factor to SI of a unit name: m, cm, mm; rad, deg; s, ms, us, ns. InputError naming --units
// and the known units otherwise.
double UnitToSi(const std::string& unit);

// "col=unit" items (e.g. {"yaw=deg", "x=mm"}) -> column -> factor to SI. InputError for an item
// without '=', an unknown unit, or a column given two different units (x=mm,x=m).
std::map<std::string, double> ParseUnits(const std::vector<std::string>& items);

// Invalid rows: refuse (rethrow the row's InputError, which names file and line) unless
// drop_invalid, then count them per file and keep the first reason.
class InvalidRows {
 public:
  explicit InvalidRows(bool drop_invalid) : drop_(drop_invalid) {}
  // Call from a catch block for the row's error: rethrows unless dropping.
  void Handle(const std::string& path, const std::string& message);
  long long total() const;
  // "dropped 3 invalid rows from a.csv (first: ...)" per file; empty when none.
  std::vector<std::string> Report() const;

 private:
  bool drop_;
  std::map<std::string, long long> count_;
  std::map<std::string, std::string> first_;
};

}  // namespace dgmm
