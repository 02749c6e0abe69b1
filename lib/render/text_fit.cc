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

namespace {

// `line` broken at `separator` into lines no wider than block_px (greedy; a piece wider than that
// stays whole). The separator's trailing space is dropped at a break ("a, b" -> "a,\nb").
std::string WrapAt(const std::string& line, const std::string& separator, double block_px, int size,
                   const std::function<double(const std::string&, int)>& width) {
  std::string out, current;
  size_t start = 0;
  while (start <= line.size()) {
    size_t cut = line.find(separator, start);
    cut = cut == std::string::npos ? line.size() : cut + separator.size() - 1;  // keep the comma
    const std::string piece = line.substr(start, cut - start);
    const std::string joined = current.empty() ? piece : current + " " + piece;
    if (!current.empty() && width(joined, size) > block_px) {
      out += (out.empty() ? "" : "\n") + current;
      current = piece;
    } else {
      current = joined;
    }
    start = cut + 1;
  }
  return out + (out.empty() ? "" : "\n") + current;
}

// f applied to each line of `text` ('\n'-separated), the results joined by '\n'.
std::string MapLines(const std::string& text,
                     const std::function<std::string(const std::string&)>& f) {
  std::string out;
  size_t start = 0;
  while (start <= text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    out += (start == 0 ? "" : "\n") + f(text.substr(start, end - start));
    start = end + 1;
  }
  return out;
}

// Breaks after commas first ("pitch -8.9 deg,\nroll -11.2 deg"), then at spaces where a line is
// still too wide.
std::string WrapLine(const std::string& line, double block_px, int size,
                     const std::function<double(const std::string&, int)>& width) {
  return MapLines(WrapAt(line, ", ", block_px, size, width), [&](const std::string& part) {
    return width(part, size) > block_px ? WrapAt(part, " ", block_px, size, width) : part;
  });
}

}  // namespace

FittedLabels FitCategoryLabels(const std::vector<std::string>& names, double block_px,
                               int font_size, int min_font_size,
                               const std::function<double(const std::string&, int)>& width) {
  FittedLabels out;
  for (int size = font_size; size >= min_font_size; --size) {
    out.labels.clear();
    out.font_size = size;
    out.fits = true;
    for (const std::string& name : names) {
      const std::string label = MapLines(name, [&](const std::string& line) {
        return width(line, size) > block_px ? WrapLine(line, block_px, size, width) : line;
      });
      out.fits = out.fits && width(label, size) <= block_px;
      out.labels.push_back(label);
    }
    if (out.fits) return out;
  }
  return out;
}

}  // namespace dgmm
