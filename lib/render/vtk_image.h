#pragma once
// Internal to dgmm_render (includes VTK): capture a rendered context view and write PNGs.
#include <vtkContextView.h>
#include <vtkImageData.h>
#include <vtkSmartPointer.h>

#include <string>
#include <vector>

namespace dgmm::render_internal {

// An offscreen context view of width x height pixels with a white background. Checks the
// display first (render/display.h).
vtkSmartPointer<vtkContextView> MakeOffscreenView(int width, int height);

// Renders the view and returns its RGB pixels (a deep copy; origin bottom-left).
vtkSmartPointer<vtkImageData> CaptureView(vtkContextView* view);

// Images of equal height placed left to right.
vtkSmartPointer<vtkImageData> AppendHorizontally(
    const std::vector<vtkSmartPointer<vtkImageData>>& images);

// Writes the image as PNG through AtomicFile; throws InputError naming the path on failure.
void WritePngAtomically(vtkImageData* image, const std::string& png_path);

}  // namespace dgmm::render_internal
