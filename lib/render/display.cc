#include "render/display.h"

#include <X11/Xlib.h>

#include <chrono>
#include <cstdlib>
#include <stdexcept>
#include <thread>

namespace dgmm {

std::optional<std::string> DisplayProblem() {
  const char* name = std::getenv("DISPLAY");
  std::string shown = name ? name : "<unset>";
  // An empty or unset DISPLAY makes Xlib fail without trying; a dead one fails on connect.
  // A server that is still starting (xvfb-run under load) gets a few short retries.
  if (name != nullptr && *name != '\0') {
    for (int attempt = 0; attempt < 4; ++attempt) {
      if (Display* display = XOpenDisplay(name)) {
        XCloseDisplay(display);
        return std::nullopt;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(250));
    }
  }
  return "cannot open an X display for rendering (DISPLAY=" + shown + "); run under xvfb-run -a";
}

void RequireDisplay() {
  if (auto problem = DisplayProblem()) throw std::runtime_error(*problem);
}

void* SharedDisplay() {
  static Display* display = nullptr;
  const char* current = std::getenv("DISPLAY");
  if (current == nullptr || *current == '\0') {
    // Unset since the connection was opened: the caller asked for no display.
    throw std::runtime_error(*DisplayProblem());
  }
  if (display == nullptr) {
    const char* name = std::getenv("DISPLAY");
    // Like DisplayProblem: a loaded Xvfb can refuse a connection made right after another
    // client closed (seen with `dgmm view`, whose window takes a while to tear down).
    for (int attempt = 0; attempt < 8 && display == nullptr && name != nullptr && *name != '\0';
         ++attempt) {
      if (attempt > 0) std::this_thread::sleep_for(std::chrono::milliseconds(250));
      display = XOpenDisplay(name);
    }
    if (display == nullptr) {
      throw std::runtime_error("cannot open an X display for rendering (DISPLAY=" +
                               std::string(name ? name : "<unset>") +
                               "); run under xvfb-run -a");
    }
  }
  return display;
}

}  // namespace dgmm
