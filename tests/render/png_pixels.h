#pragma once
// Reads a PNG back (vtkPNGReader) so rendering tests can check real pixels.
#include <Eigen/Dense>
#include <string>

namespace dgmm::test {

// Luminance 0.2126 R + 0.7152 G + 0.0722 B of each pixel; row 0 is the BOTTOM row (VTK's
// convention, the same as PlotLayout). Empty matrix when the file cannot be read.
struct PngImage {
  int width = 0, height = 0;
  Eigen::MatrixXd luminance;  // height x width
  Eigen::MatrixXd red, green, blue;
};
PngImage ReadPng(const std::string& path);

// (column, row) of the brightest pixel inside the rectangle [left, right] x [bottom, top] after a
// 5 x 5 box blur (so thin lines and single dots do not win over a bright region).
Eigen::Vector2i BrightestRegion(const PngImage& image, int left, int bottom, int right, int top);

}  // namespace dgmm::test
