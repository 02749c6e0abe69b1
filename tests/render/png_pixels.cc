#include "tests/render/png_pixels.h"

#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGReader.h>

#include <algorithm>

namespace dgmm::test {

PngImage ReadPng(const std::string& path) {
  PngImage out;
  vtkNew<vtkPNGReader> reader;
  if (!reader->CanReadFile(path.c_str())) return out;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  out.width = dims[0];
  out.height = dims[1];
  out.luminance.resize(out.height, out.width);
  out.red = out.green = out.blue = out.luminance;
  const int channels = image->GetNumberOfScalarComponents();
  for (int r = 0; r < out.height; ++r) {
    for (int c = 0; c < out.width; ++c) {
      double rgb[3];
      for (int k = 0; k < 3; ++k) {
        rgb[k] = image->GetScalarComponentAsDouble(c, r, 0, std::min(k, channels - 1));
      }
      out.red(r, c) = rgb[0];
      out.green(r, c) = rgb[1];
      out.blue(r, c) = rgb[2];
      out.luminance(r, c) = 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
    }
  }
  return out;
}

Eigen::Vector2i BrightestRegion(const PngImage& image, int left, int bottom, int right, int top) {
  double best = -1;
  Eigen::Vector2i at(-1, -1);
  for (int r = std::max(bottom + 2, 2); r <= std::min(top - 2, image.height - 3); ++r) {
    for (int c = std::max(left + 2, 2); c <= std::min(right - 2, image.width - 3); ++c) {
      double v = image.luminance.block(r - 2, c - 2, 5, 5).mean();
      if (v > best) {
        best = v;
        at = {c, r};
      }
    }
  }
  return at;
}

}  // namespace dgmm::test
