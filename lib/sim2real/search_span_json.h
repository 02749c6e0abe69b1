#pragma once
// A search's span in report.json (verdict.named[].fits_as_well and knobs.refined[].fits_as_well):
// null without a search.
#include <nlohmann/json.hpp>

#include "sim2real/json_number.h"
#include "sim2real/search_span.h"

namespace dgmm::sim2real {

inline nlohmann::json SearchSpanJson(const SearchSpan& s) {
  if (!s.Searched()) return nullptr;
  return {{"values", {JsonNumber(s.lower), JsonNumber(s.upper)}},
          {"forward_offset_m", {JsonNumber(s.x_lower), JsonNumber(s.x_upper)}},
          {"points", s.points},
          {"searched", s.searched},
          {"z", s.z}};
}

}  // namespace dgmm::sim2real
