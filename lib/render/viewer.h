#pragma once
// `dgmm view`: a VTK window over a SliceExplorer. The heat-map panels (one, or A, B and A - B) sit
// in a row at the bottom, drawn by the same chart code as `dgmm render` (heat_map_chart.h); above
// them a strip with one slider per terrain dimension, the status line, the hover read-out and the
// key bindings. Needs an X display (render/display.h).
#include <Eigen/Dense>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "render/slice_explorer.h"

namespace dgmm {

struct ViewerOptions {
  std::string save_prefix = "dgmm-view";  // key s writes <prefix>-<n>.png (n = 1, 2, ...)
  std::string record_file;                // when set, every event is recorded there (VTK format)
  // Receives one line per user-facing message (saved files, the equivalent render command).
  std::function<void(const std::string&)> on_message;
};

// The keys, one "key: action" per entry (for the window's help line and docs/viewer.md).
const std::vector<std::string>& ViewerKeyBindings();

class Viewer {
 public:
  // Opens the window (not yet interactive). Throws std::runtime_error without a display.
  Viewer(SliceExplorer explorer, ViewerOptions options);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  // Runs the event loop until the window is closed or q is pressed.
  void Run();
  // Plays a vtkInteractorEventRecorder stream (as written by record_file, or by hand) through
  // the window's interactor, then returns (no event loop).
  void Replay(const std::string& events);

  // Writes the panel row, as shown, to `png_path` (temp file + rename); returns the
  // `dgmm render` arguments drawing the same picture (empty when render has no equivalent).
  std::vector<std::string> Save(const std::string& png_path);
  // Writes the whole window (panels and controls), e.g. for documentation screenshots.
  void SaveWindow(const std::string& png_path);
  // Recomputes the panels from the explorer and renders the window.
  void Redraw();
  // What moving slider i to `value` does: the widget shows it, the explorer conditions on it
  // and the panels are redrawn.
  void MoveSlider(int i, double value);

  SliceExplorer& explorer();
  // Display pixels (bottom-left origin) of slider i's two ends: (x1, y1, x2, y2).
  std::array<double, 4> SliderPixels(int i) const;
  // Display pixel of (x, y) in data units in panel `panel` (as last drawn).
  Eigen::Vector2d PanelPixel(int panel, double x, double y) const;
  const std::string& readout() const;
  const std::vector<std::string>& saved_files() const;
  std::array<int, 2> window_size() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dgmm
