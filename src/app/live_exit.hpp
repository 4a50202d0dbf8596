#pragma once
/// The live session's exit code (`run`, headless or windowed), each non-zero one said on stderr
/// with why: the summary goes to stdout, which a log capture may not keep.
#include <string>

#include "spidar/session/live_session.hpp"

namespace spidar::app {

/// After `session->stop()`: 2 (kExitBadInput) when the recording could not be written whole,
/// 1 (kExitFault) when the servo loop latched a fault, the device stopped or the session failed,
/// else 0. `ended_by` is how the run ended ("seconds", "SIGINT", "device stopped", …).
int live_exit_code(const session::LiveSession& session, const std::string& ended_by);

}  // namespace spidar::app
