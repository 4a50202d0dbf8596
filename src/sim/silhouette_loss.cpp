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
  for (int h = 0; h < 2; ++h) off += missed[h] + spill_palm[h] + spill_digits[h];
  const long all = both + off;
  return all > 0 ? static_cast<double>(both) / static_cast<double>(all) : 1.0;
}

SilhouetteLoss& SilhouetteLoss::operator+=(const SilhouetteLoss& o) {
  for (int h = 0; h < 2; ++h) {
    missed[h] += o.missed[h];
    spill_palm[h] += o.spill_palm[h];
    spill_digits[h] += o.spill_digits[h];
  }
  both += o.both;
  return *this;
}

Status silhouette_loss(const cv::Mat& model_hand_id, const cv::Mat& real_hand_only,
                       const cv::Mat& real_hand_index, SilhouetteLoss* out) {
  const auto check = [&](const cv::Mat& m, const char* name) -> Status {
    if (m.type() != CV_8UC1) return Error{std::string("silhouette_loss: ") + name + " must be CV_8UC1"};
    if (m.size() != model_hand_id.size())
      return Error{std::string("silhouette_loss: ") + name + " is " + std::to_string(m.cols) + "x" +
                   std::to_string(m.rows) + ", the model's hand ids " + std::to_string(model_hand_id.cols) +
                   "x" + std::to_string(model_hand_id.rows)};
    return Ok{};
  };
  if (auto s = check(model_hand_id, "model_hand_id"); !s) return s;
  if (auto s = check(real_hand_only, "real_hand_only"); !s) return s;
  if (auto s = check(real_hand_index, "real_hand_index"); !s) return s;
  SilhouetteLoss l;
  for (int y = 0; y < model_hand_id.rows; ++y) {
    const std::uint8_t* id = model_hand_id.ptr<std::uint8_t>(y);
    const std::uint8_t* real = real_hand_only.ptr<std::uint8_t>(y);
    const std::uint8_t* which = real_hand_index.ptr<std::uint8_t>(y);
    for (int x = 0; x < model_hand_id.cols; ++x) {
      const render::HandId d = render::decode_hand_id(id[x]);
      const bool model = is_hand_pixel(id[x]);
      const bool is_real = real[x] != 0;
      if (model && is_real) {
        ++l.both;
      } else if (model) {
        ++(d.finger == render::kPalmPart ? l.spill_palm : l.spill_digits)[static_cast<std::size_t>(d.hand)];
      } else if (is_real && (which[x] == 1 || which[x] == 2)) {
        ++l.missed[which[x] - 1u];
      }
    }
  }
  *out = l;
  return Ok{};
}

}  // namespace spidar::sim
