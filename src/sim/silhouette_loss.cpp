#include "spidar/sim/silhouette_loss.hpp"

#include <array>
#include <string>

#include "spidar/render/hand_skin.hpp"
#include "spidar/render/renderer.hpp"

namespace spidar::sim {

bool is_hand_pixel(std::uint8_t hand_id) {
  const render::HandId d = render::decode_hand_id(hand_id);
  return hand_id != 0 && d.hand >= 0 && d.hand < 2 && d.finger != render::kForearmPart &&
         d.finger != render::kBraceletPart;
}

double SilhouetteLoss::iou() const {
  long off = 0;
  for (int h = 0; h < 2; ++h) off += missed_palm[h] + missed_digits[h] + spill_palm[h] + spill_digits[h];
  const long all = both + off;
  return all > 0 ? static_cast<double>(both) / static_cast<double>(all) : 1.0;
}

long SilhouetteLoss::real_pixels() const {
  return both + missed_palm[0] + missed_palm[1] + missed_digits[0] + missed_digits[1];
}

long SilhouetteLoss::model_pixels() const {
  return both + spill_palm[0] + spill_palm[1] + spill_digits[0] + spill_digits[1];
}

SilhouetteLoss& SilhouetteLoss::operator+=(const SilhouetteLoss& o) {
  for (int h = 0; h < 2; ++h) {
    missed_palm[h] += o.missed_palm[h];
    missed_digits[h] += o.missed_digits[h];
    spill_palm[h] += o.spill_palm[h];
    spill_digits[h] += o.spill_digits[h];
  }
  both += o.both;
  return *this;
}

namespace {

/// The two id images' types and sizes; `what` names the caller in the error.
Status check_id_images(const cv::Mat& model_hand_id, const cv::Mat& real_hand_id, const char* what) {
  const std::string w = what;
  if (model_hand_id.type() != CV_8UC1) return Error{w + ": model_hand_id must be CV_8UC1"};
  if (real_hand_id.type() != CV_8UC1) return Error{w + ": real_hand_id must be CV_8UC1"};
  if (real_hand_id.size() != model_hand_id.size())
    return Error{w + ": real_hand_id is " + std::to_string(real_hand_id.cols) + "x" +
                 std::to_string(real_hand_id.rows) + ", model_hand_id " + std::to_string(model_hand_id.cols) +
                 "x" + std::to_string(model_hand_id.rows)};
  return Ok{};
}

/// Each id's class: 0 not a hand pixel, else 1 + 2 × side + (0 palm, 1 digit). A table makes the
/// pass over the image a lookup per pixel (the truth scorer runs it two or three times a frame).
std::array<std::uint8_t, 256> hand_pixel_classes() {
  std::array<std::uint8_t, 256> cls{};
  for (int id = 1; id < 256; ++id) {
    const auto u = static_cast<std::uint8_t>(id);
    if (!is_hand_pixel(u)) continue;
    const render::HandId d = render::decode_hand_id(u);
    cls[static_cast<std::size_t>(id)] = static_cast<std::uint8_t>(1 + 2 * d.hand + (d.finger == render::kPalmPart ? 0 : 1));
  }
  return cls;
}

}  // namespace

Status silhouette_loss(const cv::Mat& model_hand_id, const cv::Mat& real_hand_id, SilhouetteLoss* out) {
  if (auto st = check_id_images(model_hand_id, real_hand_id, "silhouette_loss"); !st) return st;
  if (out == nullptr) return Error{"silhouette_loss: no output"};
  const std::array<std::uint8_t, 256> cls = hand_pixel_classes();
  std::array<long, 5> spilled{}, missed{};
  long both = 0;
  for (int y = 0; y < model_hand_id.rows; ++y) {
    const std::uint8_t* model = model_hand_id.ptr<std::uint8_t>(y);
    const std::uint8_t* real = real_hand_id.ptr<std::uint8_t>(y);
    for (int x = 0; x < model_hand_id.cols; ++x) {
      const std::uint8_t m = cls[model[x]], r = cls[real[x]];
      if ((m | r) == 0) continue;
      if (m != 0 && r != 0) ++both;
      else if (m != 0) ++spilled[m];
      else ++missed[r];
    }
  }
  SilhouetteLoss l;
  l.both = both;
  for (std::size_t h = 0; h < 2; ++h) {
    l.spill_palm[h] = spilled[1 + 2 * h];
    l.spill_digits[h] = spilled[2 + 2 * h];
    l.missed_palm[h] = missed[1 + 2 * h];
    l.missed_digits[h] = missed[2 + 2 * h];
  }
  *out = l;
  return Ok{};
}

Status silhouette_loss_image(const cv::Mat& model_hand_id, const cv::Mat& real_hand_id, cv::Mat* bgr,
                             const SilhouetteLossColours& colours) {
  if (auto st = check_id_images(model_hand_id, real_hand_id, "silhouette_loss_image"); !st) return st;
  if (bgr == nullptr) return Error{"silhouette_loss_image: no output image"};
  const std::array<std::uint8_t, 256> cls = hand_pixel_classes();
  bgr->create(model_hand_id.size(), CV_8UC3);
  bgr->setTo(cv::Scalar::all(0));
  for (int y = 0; y < model_hand_id.rows; ++y) {
    const std::uint8_t* model = model_hand_id.ptr<std::uint8_t>(y);
    const std::uint8_t* real = real_hand_id.ptr<std::uint8_t>(y);
    cv::Vec3b* o = bgr->ptr<cv::Vec3b>(y);
    for (int x = 0; x < model_hand_id.cols; ++x) {
      const std::uint8_t m = cls[model[x]], r = cls[real[x]];
      if ((m | r) == 0) continue;
      const bool digit = ((m != 0 ? m : r) - 1) % 2 == 1;
      if (m != 0 && r != 0) o[x] = colours.both;
      else if (m != 0) o[x] = digit ? colours.spill_digits : colours.spill_palm;
      else o[x] = digit ? colours.missed_digits : colours.missed_palm;
    }
  }
  return Ok{};
}

}  // namespace spidar::sim
