#include "spidar/sim/silhouette_loss.hpp"

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

Status silhouette_loss(const cv::Mat& model_hand_id, const cv::Mat& real_hand_id, SilhouetteLoss* out) {
  if (model_hand_id.type() != CV_8UC1) return Error{"silhouette_loss: model_hand_id must be CV_8UC1"};
  if (real_hand_id.type() != CV_8UC1) return Error{"silhouette_loss: real_hand_id must be CV_8UC1"};
  if (real_hand_id.size() != model_hand_id.size())
    return Error{"silhouette_loss: real_hand_id is " + std::to_string(real_hand_id.cols) + "x" +
                 std::to_string(real_hand_id.rows) + ", model_hand_id " + std::to_string(model_hand_id.cols) +
                 "x" + std::to_string(model_hand_id.rows)};
  SilhouetteLoss l;
  // A hand pixel's side (0 left, 1 right) and whether it is the palm.
  const auto side = [](std::uint8_t id) { return static_cast<std::size_t>(render::decode_hand_id(id).hand); };
  const auto palm = [](std::uint8_t id) { return render::decode_hand_id(id).finger == render::kPalmPart; };
  for (int y = 0; y < model_hand_id.rows; ++y) {
    const std::uint8_t* model = model_hand_id.ptr<std::uint8_t>(y);
    const std::uint8_t* real = real_hand_id.ptr<std::uint8_t>(y);
    for (int x = 0; x < model_hand_id.cols; ++x) {
      const bool m = is_hand_pixel(model[x]), r = is_hand_pixel(real[x]);
      if (m && r) ++l.both;
      else if (m) ++(palm(model[x]) ? l.spill_palm : l.spill_digits)[side(model[x])];
      else if (r) ++(palm(real[x]) ? l.missed_palm : l.missed_digits)[side(real[x])];
    }
  }
  *out = l;
  return Ok{};
}

}  // namespace spidar::sim
