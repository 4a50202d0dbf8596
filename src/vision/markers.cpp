#include "spidar/vision/markers.hpp"

#include "spidar/vision/pnp.hpp"
#include "spidar/vision/three_marker.hpp"

namespace spidar::vision {

MarkerSet parse_markers(const core::ConfigNode& root) {
  root.expect_keys({"markers"});
  const auto list = root["markers"];
  MarkerSet out;
  out.source = root.file();
  if (list.size() < 3) list.fail("expected at least 3 markers");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const auto n = list.at(i);
    n.expect_keys({"name", "world", "pixel", "camera"});
    Marker m;
    m.name = n.has("name") ? n["name"].as_string() : "m" + std::to_string(i + 1);
    m.p_W = n["world"].as_vec3();
    if (n.has("pixel") == n.has("camera")) n.fail("expected exactly one of pixel or camera");
    if (auto px = n.find("pixel")) {
      const auto v = px->as_doubles();
      if (v.size() != 2) px->fail("expected [u, v] in px");
      m.uv = Vec2(v[0], v[1]);
    } else {
      m.p_C = n["camera"].as_vec3();
    }
    const bool by_pixel = m.uv.has_value();
    if (i == 0) {
      out.by_pixel = by_pixel;
    } else if (by_pixel != out.by_pixel) {
      n.fail(std::string("expected `") + (out.by_pixel ? "pixel" : "camera") +
             "` like the first marker (do not mix PnP and three-marker measurements)");
    }
    out.markers.push_back(std::move(m));
  }
  if (out.by_pixel && out.markers.size() < 4) {
    list.fail("expected at least 4 markers with pixels for PnP (or 3 with camera coordinates)");
  }
  if (!out.by_pixel && out.markers.size() != 3) {
    list.fail("expected exactly 3 markers with camera coordinates (the paper's method)");
  }
  return out;
}

MarkerSet load_markers(const std::string& path) {
  return parse_markers(core::ConfigNode::LoadFile(path));
}

Result<ExtrinsicsResult> calibrate_extrinsics(const Intrinsics& intrinsics, const MarkerSet& set) {
  ExtrinsicsResult out;
  if (set.by_pixel) {
    std::vector<Vec3> p_W;
    std::vector<Vec2> uv;
    for (const auto& m : set.markers) {
      p_W.push_back(m.p_W);
      uv.push_back(*m.uv);
    }
    auto r = solve_pnp(intrinsics, p_W, uv);
    if (!r) return Error{set.source + ": " + r.error().message};
    out.X_CW = r->X_CW;
    out.method = "pnp";
    out.rms_px = r->rms_px;
    out.max_px = r->max_px;
    return out;
  }
  if (set.markers.size() != 3) return Error{set.source + ": expected exactly 3 markers"};
  std::array<MarkerPair, 3> pairs;
  for (int i = 0; i < 3; ++i) pairs[i] = {set.markers[i].p_W, *set.markers[i].p_C};
  auto r = three_marker_extrinsics(pairs);
  if (!r) return Error{set.source + ": " + r.error().message};
  out.X_CW = r->X_CW;
  out.method = "three-marker";
  out.rms_m = r->rms_m;
  return out;
}

}  // namespace spidar::vision
