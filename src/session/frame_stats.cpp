#include "spidar/session/frame_stats.hpp"

#include "spidar/core/clock.hpp"
#include "spidar/registration/metrics.hpp"

namespace spidar::session {

double silhouette_iou(const pipeline::FrameResult& r, cv::Mat* scratch) {
  if (r.virt.hand_id.empty() || r.key.silhouette.empty()) return 0.0;
  *scratch = r.virt.hand_id != 0;  // 255 where a fitted hand (or its forearm) is nearest
  return registration::mask_iou(*scratch, r.key.silhouette);
}

void FrameStatsSink::on_frame(const FrameEvent& e) {
  const pipeline::FrameResult& r = *e.result;
  FrameStats m;
  m.t_s = e.t_s;
  m.iou = silhouette_iou(r, &iou_scratch_);
  for (int h = 0; h < 2; ++h) {
    m.terms[h] = r.fits[h].terms;
    m.iterations[h] = r.fits[h].iterations;
  }
  m.latency_ms = core::ns_to_s(e.t_done_ns - e.t_exposure_ns) * 1e3;
  m.pipeline_ms = r.timings.total_ms;
  m.registration_ms = r.timings.registration_ms;
  m.servo_rate_hz = e.servo.rate_hz;
  m.servo_jitter_max_us = e.servo.jitter_max_us;
  history_.push(m);
  iou_sum_ += m.iou;
  registration_ms_sum_ += m.registration_ms;
  camera_image_ = *e.bgr;  // a header: the image stays valid until the source's next frame
  result_ = e.result;
  measured_ = *e.measured;
}

}  // namespace spidar::session
