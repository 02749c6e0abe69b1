#include "render/robot_view.h"

#include <cmath>
#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkCubeSource.h>
#include <vtkCylinderSource.h>
#include <vtkImageData.h>
#include <vtkLight.h>
#include <vtkMatrix4x4.h>
#include <vtkPlaneSource.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataAlgorithm.h>
#include <vtkPolyDataNormals.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkSphereSource.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include "render/display.h"
#include "render/vtk_image.h"
#include "util/error.h"

namespace dgmm {
namespace {

template <typename T>
using Ptr = vtkSmartPointer<T>;

// Places `source` (centred at the origin in its own frame) with rotation and translation.
void AddActor(vtkRenderer* renderer, vtkPolyDataAlgorithm* source, const Eigen::Matrix3d& r,
              const Eigen::Vector3d& t, const Eigen::Vector4d& rgba) {
  auto mapper = Ptr<vtkPolyDataMapper>::New();
  mapper->SetInputConnection(source->GetOutputPort());
  auto actor = Ptr<vtkActor>::New();
  actor->SetMapper(mapper);
  auto m = Ptr<vtkMatrix4x4>::New();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m->SetElement(i, j, r(i, j));
    m->SetElement(i, 3, t[i]);
  }
  actor->SetUserMatrix(m);
  actor->GetProperty()->SetColor(rgba[0], rgba[1], rgba[2]);
  actor->GetProperty()->SetOpacity(rgba[3]);
  actor->GetProperty()->SetSpecular(0.2);
  renderer->AddActor(actor);
}

// vtkCylinderSource's axis is y; MuJoCo's capsules and cylinders run along local z.
Eigen::Matrix3d YToZ() {
  Eigen::Matrix3d m;
  m << 1, 0, 0, 0, 0, -1, 0, 1, 0;  // maps y -> z
  return m;
}

void AddCapsuleOrCylinder(vtkRenderer* renderer, const ScenePrimitive& p) {
  auto cylinder = Ptr<vtkCylinderSource>::New();
  cylinder->SetRadius(p.size[0]);
  cylinder->SetHeight(2 * p.size[1]);
  cylinder->SetResolution(20);
  AddActor(renderer, cylinder, p.rotation * YToZ(), p.position, p.rgba);
  if (p.type != ScenePrimitive::Type::kCapsule) return;
  for (double end : {-1.0, 1.0}) {
    auto cap = Ptr<vtkSphereSource>::New();
    cap->SetRadius(p.size[0]);
    cap->SetThetaResolution(16);
    cap->SetPhiResolution(10);
    AddActor(renderer, cap, p.rotation, p.position + p.rotation * Eigen::Vector3d(0, 0, end * p.size[1]), p.rgba);
  }
}

// The grid as a plane source of that resolution, its points lifted to the heights.
void AddHeightField(vtkRenderer* renderer, const ScenePrimitive& p) {
  auto plane = Ptr<vtkPlaneSource>::New();
  const double h = 0.5 * (p.grid - 1) * p.spacing;
  plane->SetOrigin(-h, -h, 0);
  plane->SetPoint1(h, -h, 0);
  plane->SetPoint2(-h, h, 0);
  plane->SetResolution(p.grid - 1, p.grid - 1);
  plane->Update();
  auto surface = Ptr<vtkPolyData>::New();
  surface->DeepCopy(plane->GetOutput());
  vtkPoints* points = surface->GetPoints();
  for (vtkIdType i = 0; i < points->GetNumberOfPoints(); ++i) {
    double xyz[3];
    points->GetPoint(i, xyz);
    xyz[2] = p.heights[static_cast<std::size_t>(i)];
    points->SetPoint(i, xyz);
  }
  auto normals = Ptr<vtkPolyDataNormals>::New();
  normals->SetInputData(surface);
  AddActor(renderer, normals, p.rotation, p.position, p.rgba);
}

// A tile with a grid of lines on it, so motion and tilt read in a still picture.
void AddPlane(vtkRenderer* renderer, const ScenePrimitive& p) {
  auto plane = Ptr<vtkPlaneSource>::New();
  const double hx = p.size[0] > 0 ? p.size[0] : 2, hy = p.size[1] > 0 ? p.size[1] : 2;
  plane->SetOrigin(-hx, -hy, 0);
  plane->SetPoint1(hx, -hy, 0);
  plane->SetPoint2(-hx, hy, 0);
  plane->SetResolution(static_cast<int>(2 * hx / 0.25), static_cast<int>(2 * hy / 0.25));
  AddActor(renderer, plane, p.rotation, p.position, p.rgba);
  auto mapper = Ptr<vtkPolyDataMapper>::New();
  mapper->SetInputConnection(plane->GetOutputPort());
  auto grid = Ptr<vtkActor>::New();
  grid->SetMapper(mapper);
  auto m = Ptr<vtkMatrix4x4>::New();
  const Eigen::Vector3d lifted = p.position + p.rotation * Eigen::Vector3d(0, 0, 1e-3);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m->SetElement(i, j, p.rotation(i, j));
    m->SetElement(i, 3, lifted[i]);
  }
  grid->SetUserMatrix(m);
  grid->GetProperty()->SetRepresentationToWireframe();
  grid->GetProperty()->SetColor(0.3, 0.35, 0.3);
  grid->GetProperty()->LightingOff();
  renderer->AddActor(grid);
}

void AddPrimitive(vtkRenderer* renderer, const ScenePrimitive& p) {
  using Type = ScenePrimitive::Type;
  switch (p.type) {
    case Type::kBox: {
      auto box = Ptr<vtkCubeSource>::New();
      box->SetXLength(2 * p.size[0]);
      box->SetYLength(2 * p.size[1]);
      box->SetZLength(2 * p.size[2]);
      AddActor(renderer, box, p.rotation, p.position, p.rgba);
      break;
    }
    case Type::kSphere: {
      auto sphere = Ptr<vtkSphereSource>::New();
      sphere->SetRadius(p.size[0]);
      sphere->SetThetaResolution(20);
      sphere->SetPhiResolution(14);
      AddActor(renderer, sphere, p.rotation, p.position, p.rgba);
      break;
    }
    case Type::kCapsule:
    case Type::kCylinder:
      AddCapsuleOrCylinder(renderer, p);
      break;
    case Type::kHeightField:
      AddHeightField(renderer, p);
      break;
    case Type::kPlane:
      AddPlane(renderer, p);
      break;
  }
}

bool Finite(const ScenePrimitive& p) {
  if (p.type == ScenePrimitive::Type::kHeightField) {
    if (p.grid < 2 || !(p.spacing > 0) || !std::isfinite(p.spacing) ||
        p.heights.size() != static_cast<std::size_t>(p.grid) * p.grid) {
      return false;
    }
    for (float h : p.heights) {
      if (!std::isfinite(h)) return false;
    }
  }
  return p.size.allFinite() && p.position.allFinite() && p.rotation.allFinite() &&
         p.rgba.allFinite();
}

}  // namespace

std::string SceneStripOptions::Validate() const {
  if (panel_width < 16 || panel_height < 16 || panel_width > 8192 || panel_height > 8192)
    return "panel size must be 16..8192 pixels";
  if (!background.allFinite()) return "background must be finite";
  return "";
}

void RenderSceneStrip(const std::vector<SceneView>& scenes, const SceneStripOptions& options,
                      const std::string& png_path) {
  if (scenes.empty()) throw MakeInputError(png_path, "scenes", "nothing to draw");
  const std::string problem = options.Validate();
  if (!problem.empty()) throw MakeInputError(png_path, "options", problem);
  for (const auto& scene : scenes) {
    for (const auto& p : scene.primitives) {
      if (!Finite(p)) throw MakeInputError(png_path, "primitives", "non-finite geometry or a height field whose heights are not grid x grid");
    }
  }
  RequireDisplay();
  std::vector<Ptr<vtkImageData>> images;
  for (const auto& scene : scenes) {
    auto renderer = Ptr<vtkRenderer>::New();
    renderer->SetBackground(options.background[0], options.background[1], options.background[2]);
    for (const auto& p : scene.primitives) AddPrimitive(renderer, p);
    vtkCamera* camera = renderer->GetActiveCamera();
    const SceneCamera& c = scene.camera;
    camera->SetPosition(c.position.data());
    camera->SetFocalPoint(c.focal_point.data());
    camera->SetViewUp(c.view_up.data());
    camera->SetViewAngle(c.view_angle_deg);
    renderer->ResetCameraClippingRange();
    if (!scene.caption.empty()) {
      auto text = Ptr<vtkTextActor>::New();
      text->SetInput(scene.caption.c_str());
      text->GetTextProperty()->SetFontSize(16);
      text->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
      text->SetDisplayPosition(10, options.panel_height - 26);
      renderer->AddActor2D(text);
    }
    auto window = Ptr<vtkRenderWindow>::New();
    window->SetOffScreenRendering(1);
    window->SetMultiSamples(4);
    window->SetSize(options.panel_width, options.panel_height);
    window->AddRenderer(renderer);
    window->Render();
    auto grab = Ptr<vtkWindowToImageFilter>::New();
    grab->SetInput(window);
    grab->SetInputBufferTypeToRGB();
    grab->ReadFrontBufferOff();
    grab->Update();
    auto image = Ptr<vtkImageData>::New();
    image->DeepCopy(grab->GetOutput());
    images.push_back(image);
  }
  render_internal::WritePngAtomically(render_internal::AppendHorizontally(images), png_path);
}

}  // namespace dgmm
