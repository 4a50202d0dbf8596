#include "live_exit.hpp"

#include <iostream>

#include "cli_support.hpp"
#include "spidar/device/device.hpp"

namespace spidar::app {

int live_exit_code(const session::LiveSession& session, const std::string& ended_by) {
  int code = 0;
  if (const device::ServoStats st = session.servo().stats(); st.faults != 0) {
    std::cerr << "spidar-mr run: the servo loop latched " << device::fault_names(st.faults) << ": "
              << st.fault_message << " (exit code " << kExitFault << ")\n";
    code = kExitFault;
  }
  if (!session.error().empty()) {
    std::cerr << "spidar-mr run: " << session.error() << " (exit code " << kExitFault << ")\n";
    code = kExitFault;
  } else if (ended_by == "device stopped" && code == 0) {
    std::cerr << "spidar-mr run: the device stopped (exit code " << kExitFault << ")\n";
    code = kExitFault;
  }
  if (const session::SessionRecorder* r = session.recorder(); r != nullptr && !r->error().empty()) {
    std::cerr << "spidar-mr: error: --record: " << r->error() << " (the recording is incomplete)\n";
    return kExitBadInput;  // before a fault: the user's output is what is missing
  }
  return code;
}

}  // namespace spidar::app
