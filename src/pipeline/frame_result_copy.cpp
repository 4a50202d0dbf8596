#include "spidar/pipeline/frame_pipeline.hpp"

namespace spidar::pipeline {
namespace {

/// copyTo reuses the destination's buffer when size and type match; an empty source empties it.
void copy_image(const cv::Mat& from, cv::Mat& to) {
  if (from.empty()) {
    to.release();
    return;
  }
  from.copyTo(to);
}

}  // namespace

void copy_frame_result(const FrameResult& from, FrameResult* to) {
  to->hands = from.hands;
  to->models = from.models;
  to->shapes = from.shapes;
  to->fits = from.fits;
  to->restarts = from.restarts;
  to->reaches = from.reaches;
  to->bracelets = from.bracelets;
  to->toward_elbow_W = from.toward_elbow_W;
  copy_image(from.key.alpha, to->key.alpha);
  copy_image(from.key.silhouette, to->key.silhouette);
  copy_image(from.key.foreground, to->key.foreground);
  copy_image(from.virt.colour, to->virt.colour);
  copy_image(from.virt.depth, to->virt.depth);
  copy_image(from.virt.hand_depth, to->virt.hand_depth);
  copy_image(from.virt.hand_id, to->virt.hand_id);
  copy_image(from.composite, to->composite);
  copy_image(from.composite_alpha, to->composite_alpha);
  copy_image(from.other, to->other);
  copy_image(from.other_alpha, to->other_alpha);
  to->timings = from.timings;
}

}  // namespace spidar::pipeline
