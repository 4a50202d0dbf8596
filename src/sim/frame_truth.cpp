#include "spidar/sim/frame_truth.hpp"

#include <cstdio>
#include <limits>
#include <string>
#include <tuple>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "spidar/core/units.hpp"
#include "spidar/hand/kinematics.hpp"
#include "spidar/hand/render_geometry.hpp"
#include "spidar/registration/metrics.hpp"
#include "spidar/render/composite_metrics.hpp"
#include "spidar/render/hand_skin.hpp"
#include "spidar/render/overlay.hpp"

namespace spidar::sim {

Result<FrameTruthMetrics> measure_frame(const SyntheticFrame& frame,
                                        const pipeline::FrameResult& result,
                                        render::CompositeMode main_mode,
                                        const std::array<hand::HandModel, 2>& models,
                                        const std::array<hand::HandModel, 2>& truth_models,
                                        const std::array<hand::HandParams, 2>& truth,
                                        const vision::Camera& camera, FrameTruthWorkspace* ws) {
  if (result.other_alpha.empty() || result.composite_alpha.empty())
    return Error{"measure_frame: both composites are needed (FramePipelineParams::other_composite)"};
  FrameTruthMetrics m;
  for (int h = 0; h < 2; ++h) {
    const hand::HandPoints t = hand::forward_kinematics(truth_models[h], truth[h]);
    const hand::HandPoints f = hand::forward_kinematics(models[h], result.hands[h]);
    m.fingertip_mm[h] = registration::fingertip_error_m(f, t) * 1e3;
    m.joint_px[h] = registration::joint_px_error(f, t, camera);
    m.wrist_depth_mm[h] = 1e3 * (camera.depth(hand::hand_pose(result.hands[h]).p) -
                                 camera.depth(hand::hand_pose(truth[h]).p));
    {
      const Vec3 w_f = hand::hand_pose(result.hands[h]).p, w_t = hand::hand_pose(truth[h]).p;
      m.wrist_px[h] = camera.depth(w_f) > 0 && camera.depth(w_t) > 0
                          ? (camera.project(w_f) - camera.project(w_t)).norm()
                          : std::numeric_limits<double>::quiet_NaN();
    }
    m.palm_rotation_deg[h] =
        registration::palm_rotation_error_rad(result.hands[h], truth[h], truth_models[h].side) * (180.0 / units::kPi);
    hand::HandParams coupled = truth[h];
    coupled.little_independent = false;
    m.joint_px_floor[h] =
        registration::joint_px_error(hand::forward_kinematics(truth_models[h], coupled), t, camera);
  }
  // The fitted hands' own pixels, where no forearm of theirs is in front (the truth's hand_only
  // mask is filmed without a scene, so scene occlusion does not enter either); the mask for
  // callers that draw it (the registration study), the IoU and the pixel counts from the loss.
  ws->model_mask.create(result.virt.hand_id.size(), CV_8UC1);
  for (int y = 0; y < ws->model_mask.rows; ++y) {
    const std::uint8_t* id = result.virt.hand_id.ptr<std::uint8_t>(y);
    std::uint8_t* o = ws->model_mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < ws->model_mask.cols; ++x) {
      o[x] = is_hand_pixel(id[x]) ? 255 : 0;
    }
  }
  if (auto st = silhouette_loss(result.virt.hand_id, frame.hand_id, &m.loss); !st)
    return st.error();
  m.iou = m.loss.iou();
  m.real_hand_pixels = m.loss.real_pixels();
  m.fitted_hand_pixels = m.loss.model_pixels();

  if (auto st = render::truth_composite_mask(frame.mask, frame.depth, result.virt.depth,
                                             &ws->truth_alpha);
      !st)
    return st.error();
  // The hand region: the real hands and wherever either composite shows the real image, less the
  // forearms and bracelets (neither method models them; the depth compositor shows them, the
  // paper's hides them).
  cv::compare(result.composite_alpha, 0.5, ws->region, cv::CMP_GE);
  cv::compare(result.other_alpha, 0.5, ws->tmp, cv::CMP_GE);
  cv::bitwise_or(ws->region, ws->tmp, ws->region);
  cv::bitwise_or(ws->region, frame.hand_only, ws->region);
  cv::bitwise_xor(frame.mask, frame.hand_only, ws->tmp);  // forearm and bracelet pixels
  ws->region.setTo(0, ws->tmp);
  const bool depth_main = main_mode == render::CompositeMode::kDepth;
  const cv::Mat& depth_alpha = depth_main ? result.composite_alpha : result.other_alpha;
  const cv::Mat& paper_alpha = depth_main ? result.other_alpha : result.composite_alpha;
  auto d = render::occlusion_error_pct(depth_alpha, ws->truth_alpha, ws->region);
  if (!d) return d.error();
  auto p = render::occlusion_error_pct(paper_alpha, ws->truth_alpha, ws->region);
  if (!p) return p.error();
  m.occlusion_pct = *d;
  m.occlusion_pct_paper = *p;

  // The contested pixels: the real hand over a virtual object (scene depth without the hands).
  if (auto st = render::contested_mask(frame.hand_only, result.virt.depth, &ws->contested); !st)
    return st.error();
  auto cd = render::region_disagreement(depth_alpha, ws->truth_alpha, ws->contested);
  if (!cd) return cd.error();
  auto cp = render::region_disagreement(paper_alpha, ws->truth_alpha, ws->contested);
  if (!cp) return cp.error();
  m.contested_pixels = cd->pixels;
  m.contested_wrong = cd->wrong;
  m.contested_wrong_paper = cp->wrong;
  return m;
}

namespace {

/// The legend of silhouette_loss_image's colours with `loss`'s counts per hand, on `tile`.
void draw_loss_legend(const SilhouetteLoss& loss, cv::Mat* tile) {
  const SilhouetteLossColours c;
  const auto put = [&](const std::string& text, int row, const cv::Scalar& colour) {
    cv::putText(*tile, text, cv::Point(16, 56 + 26 * row), cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
  };
  const auto swatch = [&](const cv::Vec3b& v, int row) {
    cv::rectangle(*tile, cv::Rect(16, 56 + 26 * row - 12, 14, 14), cv::Scalar(v[0], v[1], v[2]), cv::FILLED);
  };
  const cv::Scalar white(230, 230, 230);
  char line[128];
  std::snprintf(line, sizeof line, "IoU %.3f  (px: left / right hand)", loss.iou());
  put(line, 0, white);
  const std::array<std::tuple<const char*, cv::Vec3b, long, long>, 5> rows{{
      {"real and model", c.both, loss.both, -1},
      {"palm missed", c.missed_palm, loss.missed_palm[0], loss.missed_palm[1]},
      {"digits missed", c.missed_digits, loss.missed_digits[0], loss.missed_digits[1]},
      {"palm spilled", c.spill_palm, loss.spill_palm[0], loss.spill_palm[1]},
      {"digits spilled", c.spill_digits, loss.spill_digits[0], loss.spill_digits[1]}}};
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const auto& [name, colour, left, right] = rows[i];
    const int row = static_cast<int>(i) + 1;
    swatch(colour, row);
    if (right < 0) std::snprintf(line, sizeof line, "     %-15s %6ld", name, left);
    else std::snprintf(line, sizeof line, "     %-15s %6ld / %ld", name, left, right);
    put(line, row, white);
  }
  put("the fit drawn as scored (skin, no forearm)", 7, cv::Scalar(170, 170, 170));
  put("against the filmed hands' palms and digits", 8, cv::Scalar(170, 170, 170));
}

}  // namespace

cv::Mat keyframe_montage(const cv::Mat& camera_bgr, const pipeline::FrameResult& result,
                         render::CompositeMode main_mode,
                         const std::array<hand::HandModel, 2>& models,
                         const vision::Camera& camera, const std::string& caption,
                         const cv::Mat* real_hand_id) {
  const int w = camera_bgr.cols, h = camera_bgr.rows;
  // The third column only where the fit's drawing and the truth agree in size (else 2×2).
  cv::Mat loss_img, legend;
  if (real_hand_id != nullptr && !result.virt.hand_id.empty()) {
    SilhouetteLoss loss;
    if (silhouette_loss(result.virt.hand_id, *real_hand_id, &loss).ok() &&
        silhouette_loss_image(result.virt.hand_id, *real_hand_id, &loss_img).ok() && loss_img.size() == camera_bgr.size()) {
      legend = cv::Mat(h, w, CV_8UC3, cv::Scalar(30, 30, 30));
      draw_loss_legend(loss, &legend);
    } else {
      loss_img.release();
    }
  }
  const int columns = loss_img.empty() ? 2 : 3;
  cv::Mat out(2 * h + 28, columns * w, CV_8UC3, cv::Scalar(30, 30, 30));
  cv::Mat matte;
  result.key.alpha.convertTo(matte, CV_8U, 255.0);
  cv::cvtColor(matte, matte, cv::COLOR_GRAY2BGR);
  for (int k = 0; k < 2; ++k) {
    render::draw_hand_wireframe(matte, camera, hand::hand_render_shapes(models[k], result.hands[k]));
    if (result.bracelets[k].found) {
      const Vec2 c = result.bracelets[k].wrist_px;
      cv::circle(matte, cv::Point(cvRound(c.x()), cvRound(c.y())), 5, cv::Scalar(0, 0, 255), 2, cv::LINE_AA);
    }
  }
  const bool depth_main = main_mode == render::CompositeMode::kDepth;
  const cv::Mat& depth_img = depth_main ? result.composite : result.other;
  const cv::Mat& paper_img = depth_main ? result.other : result.composite;
  // Row by row: camera, matte [, fit against the real hands]; depth, paper [, legend].
  const std::array<std::tuple<const cv::Mat*, const char*, int, int>, 6> tiles{{
      {&camera_bgr, "camera (synthetic)", 0, 0},
      {&matte, "matte + fitted hands", 1, 0},
      {&loss_img, "fit against the real hands", 2, 0},
      {&depth_img, "composite: depth", 0, 1},
      {&paper_img, "composite: paper", 1, 1},
      {&legend, "", 2, 1}}};
  for (const auto& [img, label, col, row] : tiles) {
    if (img->empty() || col >= columns) continue;
    const cv::Rect at(col * w, row * h, w, h);
    img->copyTo(out(at));
    cv::putText(out, label, cv::Point(at.x + 8, at.y + 20), cv::FONT_HERSHEY_SIMPLEX, 0.55,
                cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  cv::putText(out, caption, cv::Point(8, 2 * h + 20), cv::FONT_HERSHEY_SIMPLEX, 0.5,
              cv::Scalar(230, 230, 230), 1, cv::LINE_AA);
  return out;
}

}  // namespace spidar::sim
