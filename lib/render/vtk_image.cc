#include "render/vtk_image.h"

#include <vtkImageAppend.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include <fstream>

#include "render/display.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace dgmm::render_internal {

vtkSmartPointer<vtkContextView> MakeOffscreenView(int width, int height) {
  void* display = SharedDisplay();
  auto view = vtkSmartPointer<vtkContextView>::New();
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  vtkRenderWindow* window = view->GetRenderWindow();
  window->SetOffScreenRendering(1);
  window->SetMultiSamples(0);
  window->SetSize(width, height);
  // No interactor: offscreen rendering needs none, and vtkXRenderWindowInteractor opens a second
  // X connection on the first Render() (and crashes in XSync when that open fails).
  window->SetInteractor(nullptr);
  window->SetDisplayId(display);
  return view;
}

vtkSmartPointer<vtkImageData> CaptureView(vtkContextView* view) {
  view->Render();
  auto grab = vtkSmartPointer<vtkWindowToImageFilter>::New();
  grab->SetInput(view->GetRenderWindow());
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(grab->GetOutput());
  return image;
}

vtkSmartPointer<vtkImageData> AppendHorizontally(
    const std::vector<vtkSmartPointer<vtkImageData>>& images) {
  auto append = vtkSmartPointer<vtkImageAppend>::New();
  append->SetAppendAxis(0);
  for (const auto& image : images) append->AddInputData(image);
  append->Update();
  auto out = vtkSmartPointer<vtkImageData>::New();
  out->DeepCopy(append->GetOutput());
  return out;
}

void WritePngAtomically(vtkImageData* image, const std::string& png_path) {
  AtomicFile file(png_path);
  // Encoded in memory and written here: a write error (disk full) is then one line of ours, not
  // libpng's and VTK's messages on stderr.
  auto writer = vtkSmartPointer<vtkPNGWriter>::New();
  writer->WriteToMemoryOn();
  writer->SetInputData(image);
  writer->Write();
  vtkUnsignedCharArray* bytes = writer->GetResult();
  if (writer->GetErrorCode() != 0 || bytes == nullptr || bytes->GetNumberOfTuples() == 0) {
    throw MakeInputError(png_path, "", "cannot encode the PNG");
  }
  {
    std::ofstream out(file.temp_path(), std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes->GetPointer(0)),
              static_cast<std::streamsize>(bytes->GetNumberOfTuples() *
                                           bytes->GetNumberOfComponents()));
    out.close();
    if (!out) throw MakeInputError(png_path, "", "cannot write (disk full?)");
  }
  file.Commit();
}

}  // namespace dgmm::render_internal
