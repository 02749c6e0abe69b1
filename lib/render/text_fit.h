#pragma once
// Titles and tick labels that fit their room: a smaller font, line breaks (no VTK here).
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace dgmm {

// Title text and font size (pt) that fit `width` pixels: bold glyphs are about 0.6 x the font
// size wide; a long title first gets a smaller font (down to 11 pt), then a line break at the
// space nearest its middle (down to 9 pt).
std::pair<std::string, int> FitTitle(const std::string& title, int width);

// Estimated width in pixels of the widest line of `text` at `font_size` (bold).
double TextWidthPx(const std::string& text, int font_size);

// Category tick labels that fit side by side in blocks of `block_px` pixels: each label's lines
// ('\n') are wrapped at spaces where wider than the block, at font_size and then smaller sizes
// down to min_font_size, until every line fits. width(text, size) measures the widest line of a
// label in pixels. Returns the labels and the font size (min_font_size and the narrowest wrapping
// when nothing fits).
struct FittedLabels {
  std::vector<std::string> labels;
  int font_size = 0;
  bool fits = false;
};
FittedLabels FitCategoryLabels(const std::vector<std::string>& names, double block_px,
                               int font_size, int min_font_size,
                               const std::function<double(const std::string&, int)>& width);

}  // namespace dgmm
