#pragma once
// Titles that fit their image: a smaller font first, then a line break (no VTK here).
#include <string>
#include <utility>

namespace dgmm {

// Title text and font size (pt) that fit `width` pixels: bold glyphs are about 0.6 x the font
// size wide; a long title first gets a smaller font (down to 11 pt), then a line break at the
// space nearest its middle (down to 9 pt).
std::pair<std::string, int> FitTitle(const std::string& title, int width);

// Estimated width in pixels of the widest line of `text` at `font_size` (bold).
double TextWidthPx(const std::string& text, int font_size);

}  // namespace dgmm
