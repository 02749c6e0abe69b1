#include "render/viewer.h"

#include <vtkCallbackCommand.h>
#include <vtkCommand.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkCoordinate.h>
#include <vtkExtractVOI.h>
#include <vtkImageData.h>
#include <vtkInteractorEventRecorder.h>
#include <vtkInteractorStyle.h>
#include <vtkObjectFactory.h>
#include <vtkProperty2D.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkSliderRepresentation2D.h>
#include <vtkSliderWidget.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <cmath>

#include "render/display.h"
#include "render/heat_map_chart.h"
#include "render/vtk_image.h"
#include "util/error.h"

namespace dgmm {
namespace {

// Mouse and keys go to the viewer's own observers and the slider widgets only: no camera moves,
// no chart pan or tooltips, so the panels show exactly what `dgmm render` draws.
class QuietStyle : public vtkInteractorStyle {
 public:
  static QuietStyle* New();
  vtkTypeMacro(QuietStyle, vtkInteractorStyle);
  void OnChar() override {}
  void OnKeyPress() override {}
  void OnMouseMove() override {}
  void OnLeftButtonDown() override {}
  void OnLeftButtonUp() override {}
  void OnMiddleButtonDown() override {}
  void OnMiddleButtonUp() override {}
  void OnRightButtonDown() override {}
  void OnRightButtonUp() override {}
  void OnMouseWheelForward() override {}
  void OnMouseWheelBackward() override {}
};
vtkStandardNewMacro(QuietStyle);

constexpr int kLine = 22;          // pixels per text line in the control strip (above the panels)
constexpr int kSliderRow = 46;     // pixels per terrain slider
constexpr double kZoomStep = 0.8;  // wheel / + zooms the window to 80% about the cursor

}  // namespace

const std::vector<std::string>& ViewerKeyBindings() {
  static const std::vector<std::string> keys = {
      "n / p: next / previous command",
      "/ then a label and Enter: pick a command by label (prefix; Esc cancels)",
      "x / X: next / previous pose dimension on the x axis",
      "y / Y: next / previous pose dimension on the y axis",
      "c: condition on the terrain sliders / marginalise the terrain",
      "g: component ellipses (2 sigma) on / off",
      "mouse on a slider: condition on that terrain value (drag or click)",
      "Tab, then , / .: select a terrain slider, move it by -5% / +5% of its span",
      "[ / ]: narrower / wider terrain band for the samples shown",
      "wheel, + / -: zoom about the cursor / the centre (all panels)",
      "arrow keys: pan (all panels)",
      "r: window as `dgmm render` chooses it",
      "s: save the panels as PNG (prints the equivalent `dgmm render`)",
      "q: quit"};
  return keys;
}

struct Viewer::Impl {
  SliceExplorer explorer;
  ViewerOptions options;
  vtkSmartPointer<vtkRenderWindow> window = vtkSmartPointer<vtkRenderWindow>::New();
  vtkSmartPointer<vtkRenderWindowInteractor> interactor =
      vtkSmartPointer<vtkRenderWindowInteractor>::New();
  vtkSmartPointer<vtkRenderer> controls = vtkSmartPointer<vtkRenderer>::New();
  std::vector<vtkSmartPointer<vtkRenderer>> panel_renderers;
  std::vector<vtkSmartPointer<vtkContextActor>> panel_actors;
  std::vector<vtkSmartPointer<vtkChartHistogram2D>> charts;
  std::vector<HeatMapSpec> specs;
  std::vector<PlotLayout> layouts;  // per panel, in its own viewport's pixels
  std::vector<vtkSmartPointer<vtkSliderWidget>> sliders;
  vtkSmartPointer<vtkTextActor> status = vtkSmartPointer<vtkTextActor>::New();
  vtkSmartPointer<vtkTextActor> hover = vtkSmartPointer<vtkTextActor>::New();
  vtkSmartPointer<vtkTextActor> help = vtkSmartPointer<vtkTextActor>::New();
  vtkSmartPointer<vtkInteractorEventRecorder> recorder;
  vtkSmartPointer<vtkCallbackCommand> on_event = vtkSmartPointer<vtkCallbackCommand>::New();
  int panel_w = 0, panel_h = 0, strip_h = 0, panels = 1;
  int selected = 0;  // the terrain slider that , and . move
  bool typing = false;
  std::string typed, readout, message, pending_save;
  std::vector<std::string> saved;

  Impl(SliceExplorer e, ViewerOptions o) : explorer(std::move(e)), options(std::move(o)) {}

  void Say(const std::string& line) {
    message = line;
    if (options.on_message) options.on_message(line);
  }

  void Build();
  void AddPanels(double top);  // one chart renderer per panel, below `top` (viewport units)
  void AddStrip(double top);   // the control strip above `top`: help, hover and status lines
  void AddSlider(int t, int width, int height);  // terrain slider t, in a window width x height
  void StyleSlider(vtkSliderRepresentation2D* rep, int width, int height);
  void Listen();               // keys, mouse and sliders to OnKey/OnMouseMove/OnWheel; the recorder
  void UpdateTexts();
  std::vector<std::string> SaveTo(const std::string& png_path);
  void OnKey(const std::string& key);
  void OnMouseMove(int x, int y);
  void OnWheel(int x, int y, bool forward);
  // Panel index and data coordinates under a display pixel; false outside every plot area.
  bool DataAt(int x, int y, int* panel, double* u, double* v) const;

  static void Dispatch(vtkObject* caller, unsigned long event, void* client, void*);
};

void Viewer::Impl::Build() {
  specs = explorer.Panels();
  panels = static_cast<int>(specs.size());
  panel_w = specs.front().width;
  panel_h = specs.front().height;
  const int terrain = static_cast<int>(explorer.terrain().size());
  strip_h = 3 * kLine + 12 + terrain * kSliderRow;
  const int width = panels * panel_w, height = panel_h + strip_h;

  window->SetDisplayId(SharedDisplay());
  window->SetMultiSamples(0);
  window->SetSize(width, height);
  window->SetWindowName("dgmm view");
  interactor->SetRenderWindow(window);
  auto style = vtkSmartPointer<QuietStyle>::New();
  interactor->SetInteractorStyle(style);

  // Panels at the bottom-left of the window, controls above them: panel 0's viewport starts at
  // pixel (0, 0) like the offscreen view of `dgmm render`, so its pixels are the same (an offset
  // viewport can round a line end that lies on a pixel boundary to the other side).
  const double top = static_cast<double>(panel_h) / height;
  AddPanels(top);
  AddStrip(top);
  interactor->Initialize();
  for (int t = 0; t < terrain; ++t) AddSlider(t, width, height);
  Listen();
}

void Viewer::Impl::AddPanels(double top) {
  for (int i = 0; i < panels; ++i) {
    auto renderer = vtkSmartPointer<vtkRenderer>::New();
    renderer->SetBackground(1.0, 1.0, 1.0);
    renderer->SetViewport(static_cast<double>(i) / panels, 0.0,
                          static_cast<double>(i + 1) / panels, top);
    auto actor = vtkSmartPointer<vtkContextActor>::New();
    actor->GetScene()->SetRenderer(renderer);
    renderer->AddViewProp(actor);
    window->AddRenderer(renderer);
    panel_renderers.push_back(renderer);
    panel_actors.push_back(actor);
    charts.push_back(nullptr);
  }
}

void Viewer::Impl::AddStrip(double top) {
  // The strip's grey background, then the controls on a transparent layer over the whole window:
  // VTK's 2-D slider picks in the frame of a renderer at the window's origin.
  auto strip = vtkSmartPointer<vtkRenderer>::New();
  strip->SetViewport(0, top, 1, 1);
  strip->SetBackground(0.94, 0.94, 0.94);
  strip->InteractiveOff();
  window->AddRenderer(strip);
  window->SetNumberOfLayers(2);
  controls->SetLayer(1);
  controls->SetPreserveColorBuffer(1);
  controls->SetViewport(0, 0, 1, 1);
  window->AddRenderer(controls);
  int line = 0;
  for (vtkTextActor* text : {help.Get(), hover.Get(), status.Get()}) {
    text->GetTextProperty()->SetFontSize(14);
    text->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
    text->SetDisplayPosition(8, panel_h + 6 + kLine * line++);
    controls->AddActor2D(text);
  }
  help->GetTextProperty()->SetColor(0.35, 0.35, 0.35);
  help->GetTextProperty()->SetFontSize(12);
  help->SetInput("keys: n/p command  / label  x/X y/Y axes  Tab , . slider  c condition  "
                 "g ellipses  [ ] band  wheel +/- zoom  arrows pan  r reset  s save  q quit");
}

void Viewer::Impl::AddSlider(int t, int width, int height) {
  const TerrainSlider& s = explorer.terrain()[t];
  auto rep = vtkSmartPointer<vtkSliderRepresentation2D>::New();
  rep->SetMinimumValue(s.min);
  rep->SetMaximumValue(s.max);
  rep->SetValue(s.value);
  rep->SetTitleText("");  // the name goes left of the slider (below, it would meet the next)
  rep->SetLabelFormat("%.4g");
  const double y = panel_h + 3 * kLine + 12 + t * kSliderRow + kSliderRow / 2.0 - 6;
  rep->GetPoint1Coordinate()->SetCoordinateSystemToDisplay();
  rep->GetPoint1Coordinate()->SetValue(120, y);
  rep->GetPoint2Coordinate()->SetCoordinateSystemToDisplay();
  rep->GetPoint2Coordinate()->SetValue(std::max(320, width - 40), y);
  auto name = vtkSmartPointer<vtkTextActor>::New();
  name->SetInput(s.name.c_str());
  name->GetTextProperty()->SetFontSize(15);
  name->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
  name->GetTextProperty()->SetVerticalJustificationToCentered();
  name->SetDisplayPosition(8, static_cast<int>(y));
  controls->AddActor2D(name);
  StyleSlider(rep, width, height);
  auto widget = vtkSmartPointer<vtkSliderWidget>::New();
  widget->SetInteractor(interactor);
  widget->SetCurrentRenderer(controls);
  widget->SetDefaultRenderer(controls);
  widget->SetRepresentation(rep);
  widget->SetAnimationModeToJump();
  widget->AddObserver(vtkCommand::InteractionEvent, on_event);
  widget->EnabledOn();
  sliders.push_back(widget);
}

void Viewer::Impl::StyleSlider(vtkSliderRepresentation2D* rep, int width, int height) {
  // Sizes are fractions of the renderer (the window): lengths of its width, widths and
  // text heights of its height; these give pixels.
  const double w = width, h = height;
  rep->SetSliderLength(12 / w);
  rep->SetSliderWidth(18 / h);
  rep->SetTubeWidth(5 / h);
  rep->SetEndCapLength(4 / w);
  rep->SetEndCapWidth(18 / h);
  rep->SetTitleHeight(14 / h);
  rep->SetLabelHeight(13 / h);
  for (vtkTextProperty* p : {rep->GetTitleProperty(), rep->GetLabelProperty()}) {
    p->SetColor(0.1, 0.1, 0.1);
    p->ShadowOff();
    p->BoldOff();
  }
  rep->GetTubeProperty()->SetColor(0.55, 0.55, 0.55);
  rep->GetSliderProperty()->SetColor(0.2, 0.35, 0.8);
  rep->GetCapProperty()->SetColor(0.4, 0.4, 0.4);
}

void Viewer::Impl::Listen() {
  on_event->SetCallback(&Impl::Dispatch);
  on_event->SetClientData(this);
  for (unsigned long e : {vtkCommand::KeyPressEvent, vtkCommand::MouseMoveEvent,
                          vtkCommand::MouseWheelForwardEvent, vtkCommand::MouseWheelBackwardEvent}) {
    interactor->AddObserver(e, on_event);
  }
  if (!options.record_file.empty()) {
    recorder = vtkSmartPointer<vtkInteractorEventRecorder>::New();
    recorder->SetInteractor(interactor);
    recorder->KeyPressActivationOff();
    recorder->SetFileName(options.record_file.c_str());
    recorder->On();
    recorder->Record();
  }
}

void Viewer::Impl::UpdateTexts() {
  std::string line = typing ? "command: " + typed + "_" : explorer.Status();
  if (!typing && sliders.size() > 1) line += "  | , . move " + explorer.terrain()[selected].name;
  status->SetInput(line.c_str());
  hover->SetInput(readout.empty() ? "hover over a panel for the density and its component"
                                  : readout.c_str());
}

void Viewer::Impl::Dispatch(vtkObject* caller, unsigned long event, void* client, void*) {
  auto* self = static_cast<Impl*>(client);
  try {
    if (event == vtkCommand::InteractionEvent) {
      for (size_t i = 0; i < self->sliders.size(); ++i) {
        if (self->sliders[i].Get() == caller) {
          auto* rep = vtkSliderRepresentation2D::SafeDownCast(
              self->sliders[i]->GetRepresentation());
          self->explorer.SetTerrain(static_cast<int>(i), rep->GetValue());
        }
      }
      self->readout.clear();
    } else if (event == vtkCommand::KeyPressEvent) {
      const char* sym = self->interactor->GetKeySym();
      self->OnKey(sym ? sym : "");
      if (sym && std::string(sym) == "q" && !self->typing) return;
    } else if (event == vtkCommand::MouseMoveEvent) {
      const int* p = self->interactor->GetEventPosition();
      self->OnMouseMove(p[0], p[1]);
      return;
    } else if (event == vtkCommand::MouseWheelForwardEvent ||
               event == vtkCommand::MouseWheelBackwardEvent) {
      const int* p = self->interactor->GetEventPosition();
      self->OnWheel(p[0], p[1], event == vtkCommand::MouseWheelForwardEvent);
    }  // else: a redraw requested by the program (Viewer::Redraw)
  } catch (const std::exception& e) {
    self->Say(std::string("dgmm view: ") + e.what());
  }
  // Every state change redraws the panels through the same path as the first draw.
  self->specs = self->explorer.Panels();
  for (int i = 0; i < self->panels; ++i) {
    vtkContextScene* scene = self->panel_actors[i]->GetScene();
    scene->ClearItems();
    self->charts[i] = render_internal::MakeHeatMapChart(self->specs[i]);
    self->charts[i]->SetInteractive(false);
    scene->AddItem(self->charts[i]);
  }
  self->UpdateTexts();
  self->window->Render();
  self->layouts.clear();
  for (int i = 0; i < self->panels; ++i) {
    self->layouts.push_back(render_internal::ChartLayout(self->charts[i], self->specs[i]));
  }
  if (!self->pending_save.empty()) {
    const std::string path = self->pending_save;
    self->pending_save.clear();
    try {
      self->SaveTo(path);
    } catch (const std::exception& e) {
      self->Say(std::string("dgmm view: ") + e.what());
    }
  }
}

void Viewer::Impl::OnKey(const std::string& key) {
  if (typing) {
    if (key == "Return" || key == "KP_Enter") {
      typing = false;
      if (!explorer.PickCommand(typed)) Say("dgmm view: no command starts with '" + typed + "'");
    } else if (key == "Escape") {
      typing = false;
    } else if (key == "BackSpace") {
      if (!typed.empty()) typed.pop_back();
    } else if (key.size() == 1) {
      typed += key;
    } else if (key == "minus" || key == "plus" || key == "period" || key == "comma" ||
               key == "underscore" || key == "space") {
      static const std::vector<std::pair<std::string, char>> kChars = {
          {"minus", '-'}, {"plus", '+'}, {"period", '.'}, {"comma", ','},
          {"underscore", '_'}, {"space", ' '}};
      for (const auto& [name, c] : kChars) {
        if (name == key) typed += c;
      }
    }
    return;
  }
  const PlotRange w = explorer.window();
  const double cx = 0.5 * (w.x_min + w.x_max), cy = 0.5 * (w.y_min + w.y_max);
  if (key == "n" || key == "Next") explorer.StepCommand(1);
  else if (key == "p" || key == "Prior") explorer.StepCommand(-1);
  else if (key == "slash") { typing = true; typed.clear(); }
  else if (key == "x") explorer.StepX(1);
  else if (key == "X") explorer.StepX(-1);
  else if (key == "y") explorer.StepY(1);
  else if (key == "Y") explorer.StepY(-1);
  else if (key == "c") explorer.ToggleConditioned();
  else if (key == "g") explorer.ToggleEllipses();
  else if (key == "bracketleft") explorer.ScaleNearFraction(0.5);
  else if (key == "bracketright") explorer.ScaleNearFraction(2.0);
  else if (key == "plus" || key == "equal" || key == "KP_Add") explorer.Zoom(kZoomStep, cx, cy);
  else if (key == "minus" || key == "KP_Subtract") explorer.Zoom(1 / kZoomStep, cx, cy);
  else if (key == "Left") explorer.Pan(-0.1, 0);
  else if (key == "Right") explorer.Pan(0.1, 0);
  else if (key == "Up") explorer.Pan(0, 0.1);
  else if (key == "Down") explorer.Pan(0, -0.1);
  else if (key == "r") explorer.ResetWindow();
  else if (key == "Tab" && !sliders.empty()) {
    selected = (selected + 1) % static_cast<int>(sliders.size());
  }
  else if ((key == "comma" || key == "period") && !sliders.empty()) {
    const TerrainSlider& t = explorer.terrain()[selected];
    explorer.SetTerrain(selected, t.value + (key == "comma" ? -0.05 : 0.05) * (t.max - t.min));
    vtkSliderRepresentation2D::SafeDownCast(sliders[selected]->GetRepresentation())
        ->SetValue(explorer.terrain()[selected].value);
  }
  else if (key == "s") {
    // Written after this event's redraw, from the window as shown.
    pending_save = options.save_prefix + "-" + std::to_string(saved.size() + 1) + ".png";
  } else if (key == "q" || key == "Escape") interactor->TerminateApp();
}

bool Viewer::Impl::DataAt(int x, int y, int* panel, double* u, double* v) const {
  if (y >= panel_h || layouts.size() != static_cast<size_t>(panels)) return false;
  const int i = x / panel_w;
  if (i < 0 || i >= panels) return false;
  const PlotLayout& l = layouts[i];
  const double px = x - i * panel_w, py = y;
  if (px < l.left || px > l.right || py < l.bottom || py > l.top) return false;
  *panel = i;
  *u = l.range.x_min + (px - l.left) / (l.right - l.left) * (l.range.x_max - l.range.x_min);
  *v = l.range.y_min + (py - l.bottom) / (l.top - l.bottom) * (l.range.y_max - l.range.y_min);
  return true;
}

void Viewer::Impl::OnMouseMove(int x, int y) {
  int panel = 0;
  double u = 0, v = 0;
  readout = DataAt(x, y, &panel, &u, &v) ? explorer.Readout(u, v) : "";
  UpdateTexts();
  window->Render();
}

void Viewer::Impl::OnWheel(int x, int y, bool forward) {
  int panel = 0;
  double u = 0, v = 0;
  if (!DataAt(x, y, &panel, &u, &v)) {
    const PlotRange w = explorer.window();
    u = 0.5 * (w.x_min + w.x_max);
    v = 0.5 * (w.y_min + w.y_max);
  }
  explorer.Zoom(forward ? kZoomStep : 1 / kZoomStep, u, v);
}

Viewer::Viewer(SliceExplorer explorer, ViewerOptions options)
    : impl_(std::make_unique<Impl>(std::move(explorer), std::move(options))) {
  RequireDisplay();
  impl_->Build();
  Redraw();
}

Viewer::~Viewer() {
  if (!impl_) return;
  if (impl_->recorder) impl_->recorder->Off();
  // Destroy the X window and its GL context while the connection is open, rather than leaving
  // the X server to clean up after the process exits (a loaded Xvfb can then refuse the next
  // client for a while).
  impl_->window->Finalize();
}

void Viewer::Redraw() { Impl::Dispatch(nullptr, vtkCommand::ModifiedEvent, impl_.get(), nullptr); }

void Viewer::Run() { impl_->interactor->Start(); }

void Viewer::Replay(const std::string& events) {
  auto player = vtkSmartPointer<vtkInteractorEventRecorder>::New();
  player->KeyPressActivationOff();
  player->SetInteractor(impl_->interactor);
  player->ReadFromInputStringOn();
  player->SetInputString(events.c_str());
  player->Play();
  player->Off();
}

std::vector<std::string> Viewer::Save(const std::string& png_path) {
  return impl_->SaveTo(png_path);
}

namespace {

// The window's pixels (rendered now); rows [y0, y0 + height) from the bottom when height > 0.
vtkSmartPointer<vtkImageData> GrabWindow(vtkRenderWindow* window, int y0, int height) {
  auto grab = vtkSmartPointer<vtkWindowToImageFilter>::New();
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  auto image = vtkSmartPointer<vtkImageData>::New();
  if (height <= 0) {
    image->DeepCopy(grab->GetOutput());
    return image;
  }
  int full[6];
  grab->GetOutput()->GetExtent(full);
  auto crop = vtkSmartPointer<vtkExtractVOI>::New();
  crop->SetInputData(grab->GetOutput());
  crop->SetVOI(full[0], full[1], y0, y0 + height - 1, 0, 0);
  crop->Update();
  image->DeepCopy(crop->GetOutput());
  int extent[6];
  image->GetExtent(extent);
  image->SetExtent(0, extent[1] - extent[0], 0, extent[3] - extent[2], 0, 0);
  image->SetOrigin(0, 0, 0);
  return image;
}

}  // namespace

std::vector<std::string> Viewer::Impl::SaveTo(const std::string& png_path) {
  // The panel row only: pixel rows 0 .. panel_h - 1 from the bottom.
  render_internal::WritePngAtomically(GrabWindow(window, 0, panel_h), png_path);
  saved.push_back(png_path);
  std::vector<std::string> args = explorer.RenderArguments(png_path);
  std::string line = "saved " + png_path + ": " + explorer.slices().front().description;
  if (args.empty()) {
    line += "\n  (the samples near the terrain are a subset `dgmm render` has no option for)";
  } else {
    line += "\n  same picture: dgmm render";
    for (const std::string& a : args) {
      const bool quote = a.find_first_of(" ()|;") != std::string::npos;
      line += " " + (quote ? "'" + a + "'" : a);
    }
  }
  Say(line);
  return args;
}

void Viewer::MoveSlider(int i, double value) {
  auto* rep = vtkSliderRepresentation2D::SafeDownCast(
      impl_->sliders.at(static_cast<size_t>(i))->GetRepresentation());
  rep->SetValue(value);
  Impl::Dispatch(impl_->sliders[i], vtkCommand::InteractionEvent, impl_.get(), nullptr);
}

void Viewer::SaveWindow(const std::string& png_path) {
  render_internal::WritePngAtomically(GrabWindow(impl_->window, 0, 0), png_path);
}

SliceExplorer& Viewer::explorer() { return impl_->explorer; }

std::array<double, 4> Viewer::SliderPixels(int i) const {
  auto* rep = vtkSliderRepresentation2D::SafeDownCast(
      impl_->sliders.at(static_cast<size_t>(i))->GetRepresentation());
  double* p1 = rep->GetPoint1Coordinate()->GetValue();
  double* p2 = rep->GetPoint2Coordinate()->GetValue();
  return {p1[0], p1[1], p2[0], p2[1]};
}

Eigen::Vector2d Viewer::PanelPixel(int panel, double x, double y) const {
  const Impl& s = *impl_;
  Eigen::Vector2d p = s.layouts.at(static_cast<size_t>(panel)).ToPixel(x, y);
  return {p(0) + panel * s.panel_w, p(1)};
}

const std::string& Viewer::readout() const { return impl_->readout; }
const std::vector<std::string>& Viewer::saved_files() const { return impl_->saved; }
std::array<int, 2> Viewer::window_size() const {
  return {impl_->panels * impl_->panel_w, impl_->panel_h + impl_->strip_h};
}

}  // namespace dgmm
