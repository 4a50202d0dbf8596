#include "spidar/vision/bracelet.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <string>

namespace spidar::vision {
namespace {
/// The largest image the camera side reads (16384 × 16384, as a recording's frames) [px], and its
/// span: a bracelet's area, length or a distance in it beyond these describes no image.
constexpr int kMaxImagePixels = 16384 * 16384;
constexpr int kMaxImageSpanPx = 16384 * 2;
}  // namespace

Vec2 major_axis(const Eigen::Matrix2d& cov) {
  const double angle = 0.5 * std::atan2(2.0 * cov(0, 1), cov(0, 0) - cov(1, 1));
  return {std::cos(angle), std::sin(angle)};
}

Status validate(const BraceletParams& p) {
  auto bad = [](const std::string& m) { return Status(Error{"bracelet: " + m}); };
  if (p.hue_low_max < 0 || p.hue_low_max > 60) return bad("hue_low_max: expected 0..60");
  if (p.hue_high_min < 120 || p.hue_high_min > 180) return bad("hue_high_min: expected 120..180");
  if (p.saturation_min < 1 || p.saturation_min > 255) return bad("saturation_min: expected 1..255");
  if (p.value_min < 0 || p.value_min > 255) return bad("value_min: expected 0..255");
  if (p.min_area_px < 4 || p.min_area_px > kMaxImagePixels)
    return bad("min_area_px: expected 4.." + std::to_string(kMaxImagePixels) + " px, got " + std::to_string(p.min_area_px));
  if (!(p.merge_gap_px >= 0 && p.merge_gap_px <= 100)) return bad("merge_gap_px: expected 0..100");
  if (!(p.expected_length_px >= 0 && p.expected_length_px <= kMaxImageSpanPx))
    return bad("expected_length_px: expected 0.." + std::to_string(kMaxImageSpanPx) + " px");
  if (!(p.expected_aspect >= 1.0 && p.expected_aspect <= 20.0))
    return bad("expected_aspect: expected 1..20");
  if (!(p.max_prediction_distance_px > 0 && p.max_prediction_distance_px <= kMaxImageSpanPx))
    return bad("max_prediction_distance_px: expected a value in (0, " + std::to_string(kMaxImageSpanPx) + "] px");
  if (!(p.ambiguity_margin >= 0 && p.ambiguity_margin <= 1e6)) return bad("ambiguity_margin: expected 0..1e6");
  if (!(p.centre_margin_px >= 0 && p.centre_margin_px <= kMaxImageSpanPx))
    return bad("centre_margin_px: expected 0.." + std::to_string(kMaxImageSpanPx) + " px");
  return Ok{};
}

BraceletParams parse_bracelet_params(const core::ConfigNode& node) {
  node.expect_keys({"hue_low_max", "hue_high_min", "saturation_min", "value_min", "min_area_px",
                    "merge_gap_px", "expected_length_px", "expected_aspect",
                    "max_prediction_distance_px", "ambiguity_margin", "centre_margin_px",
                    "left_hand_on_image_left"});
  BraceletParams p;
  // Saturated into int: a value beyond it is out of every range below (not wrapped into one).
  auto i = [&](const char* k, int fallback) {
    return static_cast<int>(std::clamp<std::int64_t>(node.get_int(k, fallback), std::numeric_limits<int>::min(),
                                                     std::numeric_limits<int>::max()));
  };
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
  p.ambiguity_margin = node.get_double("ambiguity_margin", p.ambiguity_margin);
  p.centre_margin_px = node.get_double("centre_margin_px", p.centre_margin_px);
  if (auto v = node.find("left_hand_on_image_left")) p.left_hand_on_image_left = v->as_bool();
  if (auto s = validate(p); !s.ok()) core::fail_at_named_key(node, s.error().message, "bracelet: ");
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

Accum merged(const Accum& a, const Accum& b) {
  return {a.n + b.n, a.sx + b.sx, a.sy + b.sy, a.sxx + b.sxx, a.sxy + b.sxy, a.syy + b.syy};
}

/// Standard deviation of a pixel set across (sign −1) or along (+1) its principal axis [px].
double principal_sd(const Accum& q, double sign) {
  const double cx = q.sx / q.n, cy = q.sy / q.n;
  const double cxx = q.sxx / q.n - cx * cx, cxy = q.sxy / q.n - cx * cy, cyy = q.syy / q.n - cy * cy;
  const double half_trace = 0.5 * (cxx + cyy);
  const double d = std::sqrt(std::max(0.0, 0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy));
  return std::sqrt(std::max(0.0, half_trace + sign * d));
}
double minor_sd(const Accum& q) { return principal_sd(q, -1.0); }

/// The covariance of a pixel set [px²].
Eigen::Matrix2d covariance(const Accum& q) {
  const double cx = q.sx / q.n, cy = q.sy / q.n;
  Eigen::Matrix2d c;
  c << q.sxx / q.n - cx * cx, q.sxy / q.n - cx * cy, q.sxy / q.n - cx * cy, q.syy / q.n - cy * cy;
  return c;
}

/// Unit direction of a pixel set's principal (long) axis.
Vec2 major_axis(const Accum& q) { return vision::major_axis(covariance(q)); }

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
  const double c_fill = std::clamp(o.fill / 0.75, 0.0, 1.0);
  const double c_border = c.touches_border ? 0.3 : 1.0;
  return std::clamp(c_len * c_fill * c_border, 0.0, 1.0);
}

void find_bracelet_candidates(const cv::Mat& mask, const BraceletParams& p, BraceletWorkspace* ws,
                              double expected_length_px) {
  ws->candidates.clear();
  // Labelling only within the red pixels' bounding box (the bands are a small part of the frame);
  // the stats are moved to image coordinates, the labels stay relative to the box's corner.
  const cv::Rect box = cv::boundingRect(mask);
  if (box.area() == 0) return;
  const cv::Point label_origin = box.tl();
  ws->labels_buffer.create(mask.size(), CV_32S);  // once: the box's labels are a view into it
  ws->labels = ws->labels_buffer(cv::Rect(0, 0, box.width, box.height));
  const int n = cv::connectedComponentsWithStats(mask(box), ws->labels, ws->stats, ws->centroids,
                                                 8, CV_32S);
  for (int i = 1; i < n; ++i) {
    ws->stats.at<int>(i, cv::CC_STAT_LEFT) += label_origin.x;
    ws->stats.at<int>(i, cv::CC_STAT_TOP) += label_origin.y;
  }
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
  // Each piece's pixel moments; a group's are the sums of its pieces'.
  std::vector<Accum> acc_of(static_cast<std::size_t>(m));
  for (int a = 0; a < m; ++a) {
    const cv::Rect r = rect(pieces[a]);
    Accum& q = acc_of[static_cast<std::size_t>(a)];
    for (int y = r.y; y < r.y + r.height; ++y) {
      const int* lab = ws->labels.ptr<int>(y - label_origin.y);
      for (int x = r.x; x < r.x + r.width; ++x) {
        if (lab[x - label_origin.x] != pieces[a]) continue;
        q.n += 1;
        q.sx += x;
        q.sy += y;
        q.sxx += static_cast<double>(x) * x;
        q.sxy += static_cast<double>(x) * y;
        q.syy += static_cast<double>(y) * y;
      }
    }
  }
  // Merging: pieces whose boxes are within merge_gap_px are one band only if together they are
  // as thin as the thicker of them (a finger across a band splits it along its length; two hands'
  // bands side by side would make a thick blob). Nearest pairs first.
  std::vector<int> parent(static_cast<std::size_t>(m));
  std::iota(parent.begin(), parent.end(), 0);
  std::vector<std::array<double, 3>> pairs;  // gap, a, b
  for (int a = 0; a < m; ++a)
    for (int b = a + 1; b < m; ++b) {
      const double gap = box_gap(rect(pieces[a]), rect(pieces[b]));
      if (gap <= p.merge_gap_px) pairs.push_back({gap, static_cast<double>(a), static_cast<double>(b)});
    }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& pr : pairs) {
    const int ra = find_root(parent, static_cast<int>(pr[1]));
    const int rb = find_root(parent, static_cast<int>(pr[2]));
    if (ra == rb) continue;
    const Accum& A = acc_of[static_cast<std::size_t>(ra)];
    const Accum& B = acc_of[static_cast<std::size_t>(rb)];
    const Accum both = merged(A, B);
    const double limit = 1.35 * std::max(minor_sd(A), minor_sd(B)) + 0.5;
    if (minor_sd(both) > limit) continue;
    // Nor longer than a band can be: the pieces' boxes, along the merged axis, span at most 1.5
    // times the expected length (boxes overstate a tilted band's length a little).
    const double expected = expected_length_px > 0 ? expected_length_px : p.expected_length_px;
    if (expected > 0) {
      const Vec2 axis = major_axis(both);
      double lo = 1e300, hi = -1e300;
      for (int k = 0; k < m; ++k) {
        const int rk = find_root(parent, k);
        if (rk != ra && rk != rb) continue;
        const cv::Rect r = rect(pieces[k]);
        for (const Vec2& corner : {Vec2(r.x, r.y), Vec2(r.x + r.width, r.y), Vec2(r.x, r.y + r.height),
                                  Vec2(r.x + r.width, r.y + r.height)}) {
          lo = std::min(lo, corner.dot(axis));
          hi = std::max(hi, corner.dot(axis));
        }
      }
      if (hi - lo > 1.5 * expected) continue;
    }
    parent[static_cast<std::size_t>(ra)] = rb;
    acc_of[static_cast<std::size_t>(rb)] = both;
  }

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
    const Accum& acc = acc_of[static_cast<std::size_t>(root)];  // the group's moments
    bool border = false;
    for (int id : members) {
      const cv::Rect r = rect(id);
      border = border || r.x == 0 || r.y == 0 || r.x + r.width == mask.cols ||
               r.y + r.height == mask.rows;
    }
    const Vec2 c(acc.sx / acc.n, acc.sy / acc.n);
    const Vec2 axis = major_axis(acc);
    const Vec2 across(-axis.y(), axis.x());
    double t_min = 1e300, t_max = -1e300, s_min = 1e300, s_max = -1e300;
    for (int id : members) {
      const cv::Rect r = rect(id);
      for (int y = r.y; y < r.y + r.height; ++y) {
        const int* lab = ws->labels.ptr<int>(y - label_origin.y);
        for (int x = r.x; x < r.x + r.width; ++x) {
          if (lab[x - label_origin.x] != id) continue;
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
    o.bulge_px = -0.5 * (s_min + s_max);  // s is measured from the centroid
    o.area_px = area;
    o.pieces = static_cast<int>(members.size());
    cand.centroid_px = c;
    o.fill = area / (o.length_px * o.thickness_px);
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
  // The longest predicted band bounds how far pieces merge.
  double predicted_length = 0;
  if (pred) predicted_length = std::max(pred->length_px[0], pred->length_px[1]);
  find_bracelet_candidates(ws->mask, p, ws, predicted_length);
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

  // 1. Hands with a predicted wrist: the joint assignment of candidates to both hands (each band
  //    to at most one hand) that best matches the predictions. A match costs
  //    (distance / (gate / 3))² + (band-axis angle / 0.35 rad)² (when an axis is predicted), no
  //    match costs 9 (3 σ); matches beyond the gate or 60° off the predicted axis are not allowed.
  //    The axis tells the hands apart where both wrists project close together (the left and the
  //    right forearm cross the image at different angles). A hand whose best match is ambiguous
  //    (another choice within ambiguity_margin of its cost, for a different band) gets none.
  if (pred && (pred->wrist_px[0] || pred->wrist_px[1])) {
    const int nc = std::min<int>(static_cast<int>(cands.size()), 6);
    const double sigma_d = p.max_prediction_distance_px / 3.0;
    constexpr double kSigmaAngle = 0.35, kMaxAngle = 1.05, kNone = 9.0, kMinAxisAspect = 1.5;
    auto match_cost = [&](int h, int i) {
      if (i < 0 || !pred->wrist_px[h]) return kNone;
      const auto& o = cands[i].observation;
      const double d = (o.wrist_px - *pred->wrist_px[h]).norm();
      if (d > p.max_prediction_distance_px) return 1e9;
      double c = (d / sigma_d) * (d / sigma_d);
      // The axis only where both are defined: a band seen end-on is a ring, nearly round, whose
      // principal direction says nothing (its pixels still tell where the wrist is).
      if (pred->axis_px[h] && o.length_px > 0 && o.length_px >= kMinAxisAspect * o.thickness_px) {
        const Vec2 ax = (o.end_b_px - o.end_a_px).normalized();
        const double ang = std::acos(std::clamp(std::abs(ax.dot(pred->axis_px[h]->normalized())), 0.0, 1.0));
        if (ang > kMaxAngle) return 1e9;
        c += (ang / kSigmaAngle) * (ang / kSigmaAngle);
      }
      return c;
    };
    double best = 1e18;
    std::array<int, 2> best_pair{-1, -1};
    std::array<double, 2> runner_up{1e18, 1e18};  // per hand: best cost with a different band
    for (int i = -1; i < nc; ++i) {
      for (int j = -1; j < nc; ++j) {
        if (i >= 0 && i == j) continue;
        const double c = match_cost(0, i) + match_cost(1, j);
        if (c < best) {
          best = c;
          best_pair = {i, j};
        }
      }
    }
    // Ambiguity: the same total within ambiguity_margin with a different band for a hand.
    for (int i = -1; i < nc; ++i) {
      for (int j = -1; j < nc; ++j) {
        if (i >= 0 && i == j) continue;
        const double c = match_cost(0, i) + match_cost(1, j);
        if (i != best_pair[0]) runner_up[0] = std::min(runner_up[0], c);
        if (j != best_pair[1]) runner_up[1] = std::min(runner_up[1], c);
      }
    }
    for (int h = 0; h < 2; ++h) {
      const int i = best_pair[h];
      if (i < 0 || !pred->wrist_px[h] || best >= 1e8) continue;
      if (runner_up[h] - best < p.ambiguity_margin) continue;  // ambiguous
      finish(h, i, 1.0);
    }
  }

  // 2. Hands still without a bracelet: by image side, among candidates no hand took and that no
  //    other hand's prediction claims. A band near a hand's own prediction that its match refused
  //    (its axis past 60° from the predicted one, or ambiguous) stays open to that hand: when the
  //    previous fit's rotation has gone wrong, its predicted axis is wrong too, and refusing the
  //    band on it would keep the fit from ever getting its wrist back (the demo's right hand, as
  //    the wrist unwound after the release: lost for the last second of a run in about one in
  //    seven).
  const double mid = 0.5 * (bgr.cols - 1);
  auto hand_of_side = [&](double x) {
    const bool left_side = x < mid;
    return (left_side == p.left_hand_on_image_left) ? 0 : 1;
  };
  // Whether candidate i lies within the gate of hand h's prediction.
  auto claims = [&](int i, int h) {
    return pred && pred->wrist_px[h] &&
           (cands[i].observation.wrist_px - *pred->wrist_px[h]).norm() <= p.max_prediction_distance_px;
  };
  const bool need[2] = {chosen[0] < 0, chosen[1] < 0};
  std::vector<int> free;
  for (int i = 0; i < static_cast<int>(cands.size()) && free.size() < 2; ++i) {
    if (i == chosen[0] || i == chosen[1]) continue;
    // Open when no prediction claims it, or only the prediction of a hand still without a band.
    const int claimants = int(claims(i, 0)) + int(claims(i, 1));
    if (claimants == 0 || (claimants == 1 && need[claims(i, 0) ? 0 : 1])) free.push_back(i);
  }
  // A free band claimed by one hand's prediction goes to that hand only.
  auto may_take = [&](int h, int i) { return !claims(i, 1 - h); };
  // A hand whose prediction found nothing (the previous fit lost it, or the band moved fast) may
  // take an unclaimed band on its side, trusted a little less: a wrong prediction must not lock
  // a visible bracelet out for good.
  const double factor[2] = {pred && pred->wrist_px[0] ? 0.7 : 1.0, pred && pred->wrist_px[1] ? 0.7 : 1.0};
  if (need[0] && need[1] && free.size() == 2) {
    int a = free[0], b = free[1];
    const double xa = cands[a].centroid_px.x(), xb = cands[b].centroid_px.x();
    const bool same_side_clear = (xa < mid - p.centre_margin_px && xb < mid - p.centre_margin_px) ||
                                 (xa > mid + p.centre_margin_px && xb > mid + p.centre_margin_px);
    if (same_side_clear) {
      // Both clearly on one side: only the better one is trusted, for that side's hand.
      const int h = hand_of_side(xa);
      if (may_take(h, a)) finish(h, a, 0.5 * factor[h]);
    } else {
      if (xa > xb) std::swap(a, b);  // a is the leftmost
      const int ha = p.left_hand_on_image_left ? 0 : 1;
      if (may_take(ha, a)) finish(ha, a, factor[ha]);
      if (may_take(1 - ha, b)) finish(1 - ha, b, factor[1 - ha]);
    }
  } else {
    for (int i : free) {
      const double x = cands[i].centroid_px.x();
      if (std::abs(x - mid) <= p.centre_margin_px) continue;  // ambiguous side
      const int h = hand_of_side(x);
      if (need[h] && chosen[h] < 0 && may_take(h, i)) finish(h, i, factor[h]);
    }
  }
  return out;
}

}  // namespace spidar::vision
