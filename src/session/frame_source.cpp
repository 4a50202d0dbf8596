#include "spidar/session/frame_source.hpp"

#include <algorithm>

#include "spidar/core/clock.hpp"

namespace spidar::session {

void FrameSource::wait_for_frame(std::int64_t deadline_ns) {
  // A source that cannot say when it publishes: look again in half a millisecond.
  core::sleep_until_ns(std::min(deadline_ns, core::monotonic_ns() + 500'000));
}

}  // namespace spidar::session
