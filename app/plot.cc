// `dgmm plot`: line or bar chart of columns of a CSV file (PNG, VTK offscreen), for curves such
// as k against the number of Gaussians or cross-validation scores.
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

#include "app/command.h"
#include "render/chart.h"
#include "render/display.h"
#include "util/error.h"
#include "util/output_guard.h"

namespace dgmm::app {
namespace {

struct PlotArgs {
  std::string csv, output, x, kind = "line", title, x_label, y_label, size = "800x600";
  std::vector<std::string> y, yerr, names;
  bool log_x = false, log_y = false;
};

std::vector<std::string> SplitCsvLine(const std::string& line) {
  std::vector<std::string> cells;
  std::string cell;
  bool quoted = false;
  for (char ch : line) {
    if (ch == '"') {
      quoted = !quoted;
    } else if (ch == ',' && !quoted) {
      cells.push_back(cell);
      cell.clear();
    } else if (ch != '\r') {
      cell += ch;
    }
  }
  cells.push_back(cell);
  return cells;
}

struct Table {
  std::vector<std::string> header;
  std::vector<std::vector<std::string>> rows;
  int Column(const std::string& name, const std::string& file) const {
    for (size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return static_cast<int>(i);
    }
    throw MakeInputError(file, name, "no such column");
  }
  std::vector<double> Numbers(const std::string& name, const std::string& file) const {
    const int c = Column(name, file);
    std::vector<double> out;
    for (size_t r = 0; r < rows.size(); ++r) {
      size_t used = 0;
      double v = 0;
      try {
        v = std::stod(rows[r][c], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || used != rows[r][c].size() || !std::isfinite(v)) {
        throw MakeInputError(file, name, "row " + std::to_string(r + 2) + ": '" + rows[r][c] +
                                             "' is not a finite number");
      }
      out.push_back(v);
    }
    return out;
  }
};

Table ReadTable(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw MakeInputError(path, "", "cannot open");
  Table t;
  std::string line;
  if (!std::getline(in, line)) throw MakeInputError(path, "", "empty file");
  t.header = SplitCsvLine(line);
  while (std::getline(in, line)) {
    if (line.empty() || line == "\r") continue;
    t.rows.push_back(SplitCsvLine(line));
    if (t.rows.back().size() != t.header.size()) {
      throw MakeInputError(path, "", "row " + std::to_string(t.rows.size() + 1) + " has " +
                                         std::to_string(t.rows.back().size()) + " cells, header " +
                                         std::to_string(t.header.size()));
    }
  }
  if (t.rows.empty()) throw MakeInputError(path, "", "no data rows");
  return t;
}

void Run(const PlotArgs& args) {
  RefuseOutputThatIsAnInput(args.output, {args.csv});
  RequireDisplay();
  if (args.kind != "line" && args.kind != "bar") {
    throw MakeInputError("", "--kind", "must be line or bar");
  }
  if (!args.yerr.empty() && args.yerr.size() != args.y.size()) {
    throw MakeInputError("", "--yerr", "give one error column per y column");
  }
  int width = 0, height = 0;
  char sep = 0;
  if (std::sscanf(args.size.c_str(), "%d%c%d", &width, &sep, &height) != 3 || sep != 'x') {
    throw MakeInputError("", "--size", "expected WIDTHxHEIGHT");
  }
  const Table table = ReadTable(args.csv);
  std::vector<ChartSeries> series;
  for (size_t s = 0; s < args.y.size(); ++s) {
    ChartSeries cs;
    cs.name = s < args.names.size() ? args.names[s] : args.y[s];
    cs.y = table.Numbers(args.y[s], args.csv);
    if (!args.yerr.empty()) cs.y_error = table.Numbers(args.yerr[s], args.csv);
    if (args.kind == "line") cs.x = table.Numbers(args.x, args.csv);
    series.push_back(std::move(cs));
  }
  const std::string x_label = args.x_label.empty() ? args.x : args.x_label;
  const std::string y_label = args.y_label.empty() && args.y.size() == 1 ? args.y[0] : args.y_label;
  if (args.kind == "line") {
    LineChartSpec spec{args.title, x_label, y_label, series, args.log_x, args.log_y};
    spec.width = width;
    spec.height = height;
    RenderLineChart(spec, args.output);
  } else {
    BarChartSpec spec{args.title, x_label, y_label};
    const int c = table.Column(args.x, args.csv);
    for (const auto& row : table.rows) spec.categories.push_back(row[c]);
    spec.series = series;
    spec.width = width;
    spec.height = height;
    RenderBarChart(spec, args.output);
  }
  std::cout << "wrote " << args.output << "\n";
}

void Setup(CLI::App& root) {
  auto args = std::make_shared<PlotArgs>();
  CLI::App* cmd = root.add_subcommand(
      "plot",
      "Line or bar chart of CSV columns as PNG (needs an X display: run under `xvfb-run -a`).");
  cmd->add_option("--csv", args->csv, "CSV file with a header row")
      ->required()->check(CLI::ExistingFile);
  cmd->add_option("--x", args->x, "x column (bar charts: category labels)")->required();
  cmd->add_option("--y", args->y, "y column(s), comma separated")->required()->delimiter(',');
  cmd->add_option("--yerr", args->yerr, "error column(s), one per y column")->delimiter(',');
  cmd->add_option("--names", args->names, "legend names of the series")->delimiter(',');
  cmd->add_option("--kind", args->kind, "line or bar")->capture_default_str();
  cmd->add_option("-o,--output", args->output, "PNG to write")->required();
  cmd->add_option("--title", args->title, "chart title");
  cmd->add_option("--x-label", args->x_label, "x axis title (default: the column name)");
  cmd->add_option("--y-label", args->y_label, "y axis title");
  cmd->add_flag("--log-x", args->log_x, "logarithmic x axis");
  cmd->add_flag("--log-y", args->log_y, "logarithmic y axis");
  cmd->add_option("--size", args->size, "WIDTHxHEIGHT")->capture_default_str();
  cmd->callback([args] { Run(*args); });
}

}  // namespace

DGMM_REGISTER_COMMAND("plot", Setup);

}  // namespace dgmm::app
