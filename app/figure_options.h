#pragma once
// Option values shared by the commands that draw model slices (`render`, `view`).
#include <string>
#include <utility>
#include <vector>

#include "render/density_grid.h"

namespace dgmm::app {

// "WIDTHxHEIGHT" -> (width, height); throws InputError naming --size.
std::pair<int, int> ParseSize(const std::string& text);

// "x_min,x_max,y_min,y_max" (e.g. as `dgmm view` prints it after a zoom); throws InputError.
PlotRange ParseWindow(const std::string& text);

// ["name=value", ...] -> (name, value) pairs in raw units; throws InputError naming --condition.
std::vector<std::pair<std::string, double>> ParseConditions(const std::vector<std::string>& in);

}  // namespace dgmm::app
