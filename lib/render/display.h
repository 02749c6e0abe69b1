#pragma once
// Debian's VTK renders through X (vtkXOpenGLRenderWindow), even offscreen. Every rendering entry
// point checks for a display first, so a missing one is one clear error instead of a crash.
#include <optional>
#include <string>

namespace dgmm {

// nullopt when XOpenDisplay($DISPLAY) succeeds; otherwise the one-line reason:
// "cannot open an X display for rendering (DISPLAY=...); run under xvfb-run -a".
std::optional<std::string> DisplayProblem();

// Throws std::runtime_error(*DisplayProblem()) when no display can be opened.
void RequireDisplay();

// One X connection (a Display*) opened on first use and kept for the life of the process; every
// VTK render window uses it (SetDisplayId), so no second connection can fail mid-run.
// Throws like RequireDisplay().
void* SharedDisplay();

}  // namespace dgmm
