#include "render/text_fit.h"

#include <algorithm>
#include <cmath>

namespace dgmm {

std::pair<std::string, int> FitTitle(const std::string& title, int width) {
  const double room = std::max(100, width - 40);
  auto fits = [&](size_t chars, int size) { return 0.6 * size * chars <= room; };
  for (int size = 15; size >= 11; --size) {
    if (fits(title.size(), size)) return {title, size};
  }
  size_t cut = std::string::npos;
  for (size_t i = 0; i < title.size(); ++i) {
    if (title[i] == ' ' && (cut == std::string::npos ||
                            std::abs(2.0 * i - title.size()) < std::abs(2.0 * cut - title.size()))) {
      cut = i;
    }
  }
  if (cut == std::string::npos) return {title, 11};
  const size_t longest = std::max(cut, title.size() - cut - 1);
  int size = 15;
  while (size > 9 && !fits(longest, size)) --size;
  return {title.substr(0, cut) + "\n" + title.substr(cut + 1), size};
}


double TextWidthPx(const std::string& text, int font_size) {
  size_t longest = 0, start = 0;
  for (size_t i = 0; i <= text.size(); ++i) {
    if (i == text.size() || text[i] == '\n') {
      longest = std::max(longest, i - start);
      start = i + 1;
    }
  }
  return 0.6 * font_size * static_cast<double>(longest);
}

}  // namespace dgmm
