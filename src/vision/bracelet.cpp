#include "spidar/vision/bracelet.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <string>

namespace spidar::vision {

Status validate(const BraceletParams& p) {
  auto bad = [](const std::string& m) { return Status(Error{"bracelet: " + m}); };
  if (p.hue_low_max < 0 || p.hue_low_max > 60) return bad("hue_low_max: expected 0..60");
  if (p.hue_high_min < 120 || p.hue_high_min > 180) return bad("hue_high_min: expected 120..180");
  if (p.saturation_min < 1 || p.saturation_min > 255) return bad("saturation_min: expected 1..255");
  if (p.value_min < 0 || p.value_min > 255) return bad("value_min: expected 0..255");
  if (p.min_area_px < 4) return bad("min_area_px: expected at least 4");
  if (!(p.merge_gap_px >= 0 && p.merge_gap_px <= 100)) return bad("merge_gap_px: expected 0..100");
  if (!(p.expected_length_px >= 0)) return bad("expected_length_px: expected >= 0");
  if (!(p.expected_aspect >= 1.0 && p.expected_aspect <= 20.0))
    return bad("expected_aspect: expected 1..20");
  if (!(p.max_prediction_distance_px > 0)) return bad("max_prediction_distance_px: expected > 0");
  if (!(p.ambiguity_ratio > 0 && p.ambiguity_ratio < 1)) return bad("ambiguity_ratio: expected (0, 1)");
  if (!(p.centre_margin_px >= 0)) return bad("centre_margin_px: expected >= 0");
  return Ok{};
}

BraceletParams parse_bracelet_params(const core::ConfigNode& node) {
  node.expect_keys({"hue_low_max", "hue_high_min", "saturation_min", "value_min", "min_area_px",
                    "merge_gap_px", "expected_length_px", "expected_aspect",
                    "max_prediction_distance_px", "ambiguity_ratio", "centre_margin_px",
                    "left_hand_on_image_left"});
  BraceletParams p;
  auto i = [&](const char* k, int fallback) { return static_cast<int>(node.get_int(k, fallback)); };
  p.hue_low_max = i("hue_low_max", p.hue_low_max);
  p.hue_high_min = i("hue_high_min", p.hue_high_min);
  p.saturation_min = i("saturation_min", p.saturation_min);
  p.value_min = i("value_min", p.value_min);
  p.min_area_px = i("min_area_px", p.min_area_px);
  p.merge_gap_px = node.get_double("merge_gap_px", p.merge_gap_px);
  p.expected_length_px = node.get_double("expected_length_px", p.expected_length_px);
  p.expected_aspect = node.get_double("expected_aspect", p.expected_aspect);
  p.max_prediction_distance_px =
      node.get_double("max_prediction_distance_px", p.max_prediction_distance_px);
  p.ambiguity_ratio = node.get_double("ambiguity_ratio", p.ambiguity_ratio);
  p.centre_margin_px = node.get_double("centre_margin_px", p.centre_margin_px);
  if (auto v = node.find("left_hand_on_image_left")) p.left_hand_on_image_left = v->as_bool();
  if (auto s = validate(p); !s.ok()) node.fail(s.error().message);
  return p;
}

Status red_mask(const cv::Mat& bgr, const BraceletParams& p, cv::Mat* mask) {
  if (bgr.empty() || bgr.type() != CV_8UC3) {
    return Error{"bracelet: expected a non-empty 8-bit BGR frame (CV_8UC3)"};
  }
  mask->create(bgr.rows, bgr.cols, CV_8UC1);
  // OpenCV 8-bit HSV with R the largest channel: H = round(30 (G − B) / diff) (+180 if < 0),
  // S = round(255 diff / V), V = R. Red hues need R to be the largest channel. The inequalities
  // below are those roundings written without division.
  const int low = 2 * p.hue_low_max + 1;          // 60 (G − B) < low · diff        (G ≥ B)
  const int high = 2 * p.hue_high_min - 361;      // 60 (G − B) ≥ high · diff       (G < B)
  const int s2 = 2 * p.saturation_min - 1;        // 510 diff ≥ s2 · V
  const int vmin = p.value_min;
  for (int y = 0; y < bgr.rows; ++y) {
    const std::uint8_t* px = bgr.ptr<std::uint8_t>(y);
    std::uint8_t* m = mask->ptr<std::uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      const int b = px[3 * x], g = px[3 * x + 1], r = px[3 * x + 2];
      const int mn = std::min(g, b);
      const int diff = r - mn;
      const int gb = 60 * (g - b);
      const bool red_max = r >= g && r >= b && r >= vmin && 510 * diff >= s2 * r && diff > 0;
      const bool hue_ok = g >= b ? gb < low * diff : gb >= high * diff;
      m[x] = (red_max && hue_ok) ? 255 : 0;
    }
  }
  return Ok{};
}

namespace {

struct Accum {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
};

int find_root(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

double box_gap(const cv::Rect& a, const cv::Rect& b) {
  const int dx = std::max({0, b.x - (a.x + a.width), a.x - (b.x + b.width)});
  const int dy = std::max({0, b.y - (a.y + a.height), a.y - (b.y + b.height)});
  return std::hypot(dx, dy);
}

}  // namespace

double bracelet_confidence(const BraceletCandidate& c, const BraceletParams& p,
                           double expected_length_px) {
  const auto& o = c.observation;
  double expected = expected_length_px > 0 ? expected_length_px : p.expected_length_px;
  if (!(expected > 0)) expected = p.expected_aspect * std::max(o.thickness_px, 1.0);
  const double ratio = o.length_px / expected;
  double c_len = 1.0;
  // Within [0.85, 1.25] of the expectation: whole (perspective and wrist sizes vary a little).
  if (ratio < 0.85) c_len = std::pow(ratio / 0.85, 4.0);     // partly hidden: ends are wrong
  if (ratio > 1.25) c_len = std::pow(1.25 / ratio, 3.0);     // longer than a band: not one
  const double c_fill = std::clamp(c.fill / 0.75, 0.0, 1.0);
  const double c_border = c.touches_border ? 0.3 : 1.0;
  return std::clamp(c_len * c_fill * c_border, 0.0, 1.0);
}

void find_bracelet_candidates(const cv::Mat& mask, const BraceletParams& p, BraceletWorkspace* ws,
                              double expected_length_px) {
  ws->candidates.clear();
  const int n = cv::connectedComponentsWithStats(mask, ws->labels, ws->stats, ws->centroids, 8,
                                                 CV_32S);
  // Pieces: components large enough to be part of a band (a band cut by a finger gives pieces
  // smaller than a whole band).
  std::vector<int> pieces;
  const int piece_min = std::max(4, p.min_area_px / 4);
  for (int i = 1; i < n; ++i) {
    if (ws->stats.at<int>(i, cv::CC_STAT_AREA) >= piece_min) pieces.push_back(i);
  }
  std::sort(pieces.begin(), pieces.end(), [&](int a, int b) {
    return ws->stats.at<int>(a, cv::CC_STAT_AREA) > ws->stats.at<int>(b, cv::CC_STAT_AREA);
  });
  if (pieces.size() > 32) pieces.resize(32);
  auto rect = [&](int i) {
    return cv::Rect(ws->stats.at<int>(i, cv::CC_STAT_LEFT), ws->stats.at<int>(i, cv::CC_STAT_TOP),
                    ws->stats.at<int>(i, cv::CC_STAT_WIDTH),
                    ws->stats.at<int>(i, cv::CC_STAT_HEIGHT));
  };
  const int m = static_cast<int>(pieces.size());
  std::vector<int> parent(static_cast<std::size_t>(m));
  std::iota(parent.begin(), parent.end(), 0);
  for (int a = 0; a < m; ++a)
    for (int b = a + 1; b < m; ++b)
      if (box_gap(rect(pieces[a]), rect(pieces[b])) <= p.merge_gap_px)
        parent[find_root(parent, a)] = find_root(parent, b);

  for (int root = 0; root < m; ++root) {
    if (find_root(parent, root) != root) continue;
    std::vector<int> members;
    int area = 0;
    for (int a = 0; a < m; ++a) {
      if (find_root(parent, a) == root) {
        members.push_back(pieces[a]);
        area += ws->stats.at<int>(pieces[a], cv::CC_STAT_AREA);
      }
    }
    if (area < p.min_area_px) continue;
    // Moments over the members' pixels.
    Accum acc;
    bool border = false;
    for (int id : members) {
      const cv::Rect r = rect(id);
      border = border || r.x == 0 || r.y == 0 || r.x + r.width == mask.cols ||
               r.y + r.height == mask.rows;
      for (int y = r.y; y < r.y + r.height; ++y) {
        const int* lab = ws->labels.ptr<int>(y);
        for (int x = r.x; x < r.x + r.width; ++x) {
          if (lab[x] != id) continue;
          acc.n += 1;
          acc.sx += x;
          acc.sy += y;
          acc.sxx += static_cast<double>(x) * x;
          acc.sxy += static_cast<double>(x) * y;
          acc.syy += static_cast<double>(y) * y;
        }
      }
    }
    const Vec2 c(acc.sx / acc.n, acc.sy / acc.n);
    const double cxx = acc.sxx / acc.n - c.x() * c.x();
    const double cxy = acc.sxy / acc.n - c.x() * c.y();
    const double cyy = acc.syy / acc.n - c.y() * c.y();
    const double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy);  // major axis
    const Vec2 axis(std::cos(angle), std::sin(angle));
    const Vec2 across(-axis.y(), axis.x());
    double t_min = 1e300, t_max = -1e300, s_min = 1e300, s_max = -1e300;
    for (int id : members) {
      const cv::Rect r = rect(id);
      for (int y = r.y; y < r.y + r.height; ++y) {
        const int* lab = ws->labels.ptr<int>(y);
        for (int x = r.x; x < r.x + r.width; ++x) {
          if (lab[x] != id) continue;
          const Vec2 d(x - c.x(), y - c.y());
          const double t = d.dot(axis), s = d.dot(across);
          t_min = std::min(t_min, t);
          t_max = std::max(t_max, t);
          s_min = std::min(s_min, s);
          s_max = std::max(s_max, s);
        }
      }
    }
    BraceletCandidate cand;
    auto& o = cand.observation;
    // Pixel centres span (extent − 1); the band's ends lie half a pixel beyond them.
    o.end_a_px = c + (t_min - 0.5) * axis;
    o.end_b_px = c + (t_max + 0.5) * axis;
    o.wrist_px = 0.5 * (o.end_a_px + o.end_b_px);
    o.length_px = t_max - t_min + 1.0;
    o.thickness_px = s_max - s_min + 1.0;
    o.area_px = area;
    o.pieces = static_cast<int>(members.size());
    cand.centroid_px = c;
    cand.fill = area / (o.length_px * o.thickness_px);
    cand.touches_border = border;
    o.confidence = bracelet_confidence(cand, p, expected_length_px);
    ws->candidates.push_back(cand);
  }
  std::sort(ws->candidates.begin(), ws->candidates.end(), [](const auto& a, const auto& b) {
    return a.observation.confidence * a.observation.area_px >
           b.observation.confidence * b.observation.area_px;
  });
}

Result<std::array<BraceletObservation, 2>> detect_bracelets(const cv::Mat& bgr,
                                                            const BraceletParams& p,
                                                            const BraceletPrediction* pred,
                                                            BraceletWorkspace* ws) {
  if (auto s = validate(p); !s.ok()) return s.error();
  if (auto s = red_mask(bgr, p, &ws->mask); !s.ok()) return s.error();
  find_bracelet_candidates(ws->mask, p, ws);
  const auto& cands = ws->candidates;
  std::array<BraceletObservation, 2> out{};
  std::array<int, 2> chosen{-1, -1};

  // Without a configured or predicted length, a band that looks whole (by its aspect ratio)
  // sets the expected length for the others: both wrists are about as wide and as far away.
  double reference_length = 0;
  if (!(p.expected_length_px > 0)) {
    for (const auto& c : cands) {
      if (c.observation.confidence >= 0.8) {
        reference_length = std::max(reference_length, c.observation.length_px);
      }
    }
  }
  auto finish = [&](int hand, int idx, double factor) {
    chosen[hand] = idx;
    out[hand] = cands[idx].observation;
    out[hand].found = true;
    double expected = pred ? pred->length_px[hand] : 0.0;
    if (!(expected > 0) && reference_length > 0) expected = reference_length;
    out[hand].confidence = bracelet_confidence(cands[idx], p, expected) * factor;
  };

  // 1. Hands with a predicted wrist: nearest candidate, gated, unambiguous.
  for (int h = 0; h < 2 && pred; ++h) {
    if (!pred->wrist_px[h]) continue;
    const auto& other = pred->wrist_px[1 - h];
    int best = -1;
    double best_d = 0;
    for (int i = 0; i < static_cast<int>(cands.size()); ++i) {
      const double d = (cands[i].observation.wrist_px - *pred->wrist_px[h]).norm();
      if (d > p.max_prediction_distance_px) continue;
      if (other && d > p.ambiguity_ratio * (cands[i].observation.wrist_px - *other).norm()) continue;
      if (best < 0 || d < best_d) {
        best = i;
        best_d = d;
      }
    }
    if (best >= 0) finish(h, best, 1.0);
  }

  // 2. Hands without a prediction: by image side, among candidates no predicted hand took and
  //    that are not claimed by the other hand's prediction.
  const double mid = 0.5 * (bgr.cols - 1);
  auto hand_of_side = [&](double x) {
    const bool left_side = x < mid;
    return (left_side == p.left_hand_on_image_left) ? 0 : 1;
  };
  std::vector<int> free;
  for (int i = 0; i < static_cast<int>(cands.size()) && free.size() < 2; ++i) {
    if (i == chosen[0] || i == chosen[1]) continue;
    bool claimed = false;
    for (int h = 0; h < 2 && pred; ++h) {
      if (pred->wrist_px[h] && (cands[i].observation.wrist_px - *pred->wrist_px[h]).norm() <=
                                   p.max_prediction_distance_px)
        claimed = true;
    }
    if (!claimed) free.push_back(i);
  }
  const bool need[2] = {!(pred && pred->wrist_px[0]), !(pred && pred->wrist_px[1])};
  if (need[0] && need[1] && free.size() == 2) {
    int a = free[0], b = free[1];
    const double xa = cands[a].centroid_px.x(), xb = cands[b].centroid_px.x();
    const bool same_side_clear = (xa < mid - p.centre_margin_px && xb < mid - p.centre_margin_px) ||
                                 (xa > mid + p.centre_margin_px && xb > mid + p.centre_margin_px);
    if (same_side_clear) {
      // Both clearly on one side: only the better one is trusted, for that side's hand.
      finish(hand_of_side(xa), a, 0.5);
    } else {
      if (xa > xb) std::swap(a, b);  // a is the leftmost
      finish(p.left_hand_on_image_left ? 0 : 1, a, 1.0);
      finish(p.left_hand_on_image_left ? 1 : 0, b, 1.0);
    }
  } else {
    for (int i : free) {
      const double x = cands[i].centroid_px.x();
      if (std::abs(x - mid) <= p.centre_margin_px) continue;  // ambiguous side
      const int h = hand_of_side(x);
      if (need[h] && chosen[h] < 0) finish(h, i, 1.0);
    }
  }
  return out;
}

}  // namespace spidar::vision
