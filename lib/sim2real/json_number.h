#pragma once
// A number in report.json: null when it is not finite (NaN: not applicable).
#include <cmath>
#include <nlohmann/json.hpp>

namespace dgmm::sim2real {

inline nlohmann::json JsonNumber(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace dgmm::sim2real
