#include "spidar/session/frame_sink.hpp"

#include "spidar/core/clock.hpp"

namespace spidar::session {

void SinkGroup::on_start() {
  for (FrameSink* k : sinks_) k->on_start();
}

void SinkGroup::on_frame(const FrameEvent& e) {
  const std::int64_t t0 = core::monotonic_ns();
  for (FrameSink* k : sinks_) k->on_frame(e);
  last_ms_ = core::ns_to_s(core::monotonic_ns() - t0) * 1e3;
}

void SinkGroup::on_end(const SessionSummary& s) {
  for (FrameSink* k : sinks_) k->on_end(s);
}

}  // namespace spidar::session
