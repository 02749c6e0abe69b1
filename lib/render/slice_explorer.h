#pragma once
// The state behind `dgmm view` (no VTK): which command, which two pose dimensions, the terrain
// values z the density is conditioned on (eqs. 15-19), the plot window, and the panels it draws,
// built by SliceHeatMaps exactly as `dgmm render` builds them.
#include <Eigen/Dense>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/motion_model.h"
#include "core/sample_set.h"
#include "render/density_grid.h"
#include "render/heat_map.h"
#include "render/model_slice.h"
#include "render/slice_figure.h"

namespace dgmm {

struct ExplorerInputs {
  MotionModel model;
  std::string model_file;
  std::optional<MotionModel> compare;  // B of the A, B, A - B comparison
  std::string compare_file;
  std::optional<SampleSet> data;
  std::string data_file;
};

struct ExplorerOptions {
  SliceFigureOptions figure;   // panel size, grid, contours (as `dgmm render`)
  std::string command;         // first command shown (id or label; empty: the first)
  std::string x_dim, y_dim;    // pose dimensions shown (empty: the first two)
  std::vector<std::pair<std::string, double>> terrain;  // initial terrain values (raw units)
  // A sample is "near" the chosen terrain when every terrain coordinate is within this fraction
  // of its slider's span of the slider value (the span comes from the data or the model).
  double near_fraction = 0.1;
  bool ellipses = false;       // component ellipses (2 sigma) on the density panels
  // Empty when usable; otherwise what is wrong.
  std::string Validate() const;
};

// One slider per terrain dimension: [min, max] spans the data (or the model's 3-sigma extent).
struct TerrainSlider {
  std::string name;
  double min = 0, max = 1, value = 0;
};

class SliceExplorer {
 public:
  // Throws InputError naming the file: no commands, fewer than 2 pose dimensions, unknown
  // picks, a compare model with other dimensions or no command in common, data of other dims.
  SliceExplorer(ExplorerInputs inputs, const ExplorerOptions& options);

  // Commands shown (those of A, and of B when comparing), in id order, as their labels.
  const std::vector<std::string>& command_labels() const { return command_labels_; }
  int command_index() const { return command_index_; }
  void StepCommand(int step);  // cyclic
  // The first command whose label equals `text`, else starts with it; false when none.
  bool PickCommand(const std::string& text);
  // Cycle the x or y axis through the pose dimensions; reaching the other axis swaps the two.
  void StepX(int step);
  void StepY(int step);

  const std::vector<TerrainSlider>& terrain() const { return terrain_; }
  // Clamped to the slider's span. The window is held while the terrain moves (the axes stay put
  // and the density moves in them); a change of command, axes or conditioning frames it again
  // unless the user zoomed or panned.
  void SetTerrain(int i, double value);
  // Conditioned on the sliders (default) or marginal over the terrain.
  bool conditioned() const { return conditioned_; }
  void ToggleConditioned();
  bool ellipses() const { return ellipses_; }
  void ToggleEllipses() { ellipses_ = !ellipses_; }
  double near_fraction() const { return near_fraction_; }
  void ScaleNearFraction(double factor);  // kept in [0.01, 1]

  // The plot window: chosen as `dgmm render` does (SliceWindow) until zoomed, panned or held by a
  // terrain move.
  PlotRange window() const;
  bool window_locked() const { return locked_window_.has_value(); }
  void Zoom(double factor, double x, double y);  // factor < 1 zooms in, about (x, y)
  void Pan(double fx, double fy);                // by fractions of the window's width, height
  void ResetWindow() {
    locked_window_.reset();
    held_by_terrain_ = false;
  }

  // Current slices (A, then B) over the two shown dimensions.
  const std::vector<ModelSlice>& slices() const { return slices_; }
  // Samples of the command near the chosen terrain (all of its samples when not conditioned)
  // in raw units, rows = (x, y); empty without data.
  const Eigen::MatrixX2d& points() const { return points_; }
  // The figure: [p] or [p_A, p_B, p_A - p_B], with ellipses when on.
  std::vector<HeatMapSpec> Panels() const;

  // "x=.. y=.. p=.. component c of K (weight w%)" for each model at (x, y) in data units.
  std::string Readout(double x, double y) const;
  // One line: command, dimensions, conditions, window.
  std::string Status() const;
  // Arguments of `dgmm render` (after "render") drawing the same picture to `png`; empty when
  // render cannot (the points near the terrain are a subset render has no option for).
  std::vector<std::string> RenderArguments(const std::string& png) const;

 private:
  // The constructor's parts: the commands shown (both models' when comparing), the data checked
  // against the model; the command shown first and the x and y pose dimensions; one slider per
  // terrain dimension, spanning the data's terrain (else the model's 3-sigma extent) and set to
  // the options' conditions.
  void ListCommands();
  void PickCommandAndAxes(const ExplorerOptions& options);
  void MakeSliders(const ExplorerOptions& options);
  // Recomputes slices and points after a change of picks; a window held by a terrain move is
  // released unless keep_window.
  void Update(bool keep_window = false);

  ExplorerInputs in_;
  SliceFigureOptions figure_;
  std::vector<int> command_ids_;
  std::vector<std::string> command_labels_;
  std::vector<std::string> names_;  // of y = x || z
  int command_index_ = 0, x_index_ = 0, y_index_ = 1;
  std::vector<TerrainSlider> terrain_;
  bool conditioned_ = true, ellipses_ = false;
  double near_fraction_ = 0.1;
  std::optional<PlotRange> locked_window_;
  bool held_by_terrain_ = false;  // locked_window_ set by SetTerrain, not by the user
  std::vector<ModelSlice> slices_;
  Eigen::MatrixX2d points_;
};

// 2-sigma ellipse of each component of a 2-D mixture as a closed polyline of `segments` pieces.
std::vector<CurveOverlay> ComponentEllipses(const Mixture& mixture2d, int segments = 48);

}  // namespace dgmm
