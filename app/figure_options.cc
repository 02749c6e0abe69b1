#include "app/figure_options.h"

#include <cstdio>
#include <stdexcept>

#include "util/error.h"

namespace dgmm::app {

std::pair<int, int> ParseSize(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X')) {
    throw MakeInputError("", "--size", "expected WIDTHxHEIGHT, got '" + text.substr(0, 80) + "'");
  }
  // The limits of the heat map and chart writers, checked here so the message names the flag.
  if (w < 200 || h < 150 || w > 8000 || h > 8000) {
    throw MakeInputError("", "--size", "expected 200x150 to 8000x8000 pixels, got '" + text + "'");
  }
  return {w, h};
}

PlotRange ParseWindow(const std::string& text) {
  PlotRange r;
  char extra = 0;
  if (std::sscanf(text.c_str(), "%lf,%lf,%lf,%lf%c", &r.x_min, &r.x_max, &r.y_min, &r.y_max,
                  &extra) != 4 ||
      !r.IsValid()) {
    throw MakeInputError("", "--window", "expected x_min,x_max,y_min,y_max with min < max, got '" +
                                             text + "'");
  }
  return r;
}

std::vector<std::pair<std::string, double>> ParseConditions(const std::vector<std::string>& in) {
  std::vector<std::pair<std::string, double>> out;
  for (const std::string& c : in) {
    auto eq = c.find('=');
    size_t used = 0;
    double value = 0;
    bool ok = eq != std::string::npos && eq > 0;
    if (ok) {
      try {
        value = std::stod(c.substr(eq + 1), &used);
        ok = used == c.size() - eq - 1;
      } catch (const std::exception&) {
        ok = false;
      }
    }
    if (!ok) throw MakeInputError("", "--condition", "expected name=value, got '" + c + "'");
    out.emplace_back(c.substr(0, eq), value);
  }
  return out;
}

}  // namespace dgmm::app
