#pragma once
/// The live session's window: Dear ImGui over the GLFW window. The mixed-reality view (switchable
/// to virtual only, camera only, matte, virtual-hand overlay) and panels for the device (string
/// lengths and tensions, fingertip forces, loop rate and jitter, faults, emergency stop), the
/// registration (IoU, per-term costs, iterations) and the scene (reset, scramble, cube state).
/// With the simulated user under interactive control, the keyboard and mouse move and close the
/// hands (live_hands.hpp).
#include <atomic>
#include <string>

#include "spidar/session/live_config.hpp"
#include "spidar/session/live_session.hpp"

namespace spidar::app {

/// Runs the session in a window until it is closed, `seconds` pass (0: no limit), `signal`
/// becomes non-zero (SIGINT/SIGTERM) or the session ends. With `screenshot`, the window's last
/// frame (default framebuffer, glReadPixels) is written there as PNG. Returns the exit code.
int run_gui(const session::LiveConfig& config, const session::LiveSessionOptions& options, double seconds,
            const std::string& screenshot, std::atomic<int>& signal);

}  // namespace spidar::app
