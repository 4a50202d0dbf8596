#include "spidar/vision/marker_calibration.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <utility>

#include "spidar/core/units.hpp"

namespace spidar::vision {

MarkerCalibration::MarkerCalibration(const Camera& present, std::string measured_with)
    : present_(present), measured_with_(std::move(measured_with)) {}

Status MarkerCalibration::touched(const Vec3& p_W, double held_spread_m) {
  if (!p_W.allFinite())
    return Error{"camera calibration: the measured marker position is not finite"};
  CapturedMarker m;
  m.name = "m" + std::to_string(markers_.size() + 1);
  m.p_W = p_W;
  m.held_spread_m = held_spread_m;
  pending_ = m;
  return Ok{};
}

Status MarkerCalibration::set_pixel(const Vec2& uv) {
  if (!pending_) return Error{"camera calibration: no marker waits for a click (touch one first)"};
  const auto& in = present_.intrinsics();
  if (!uv.allFinite() || uv.x() < 0 || uv.y() < 0 || uv.x() >= in.width || uv.y() >= in.height) {
    char b[160];
    std::snprintf(b, sizeof b,
                  "camera calibration: pixel (%.1f, %.1f) of %s is outside the %dx%d image", uv.x(),
                  uv.y(), pending_->name.c_str(), in.width, in.height);
    return Error{b};
  }
  CapturedMarker m = *pending_;
  m.uv = uv;
  m.range_m = (present_.to_camera(m.p_W)).norm();
  markers_.push_back(m);
  pending_.reset();
  return Ok{};
}

Status MarkerCalibration::set_range(std::size_t i, double range_m) {
  if (i >= markers_.size())
    return Error{"camera calibration: marker " + std::to_string(i + 1) + " does not exist (have " +
                 std::to_string(markers_.size()) + ")"};
  if (!std::isfinite(range_m) || range_m <= 0.05)
    return Error{"camera calibration: range of " + markers_[i].name +
                 " must be a distance > 0.05 m, got " + std::to_string(range_m)};
  markers_[i].range_m = range_m;
  return Ok{};
}

void MarkerCalibration::remove_last() {
  if (pending_)
    pending_.reset();
  else if (!markers_.empty())
    markers_.pop_back();
}

Result<MarkerSet> MarkerCalibration::marker_set() const {
  if (markers_.size() < 3)
    return Error{"camera calibration: " + std::to_string(markers_.size()) +
                 " markers, expected 3 (the paper's three-marker method) or at least 4 (PnP)"};
  MarkerSet set;
  set.by_pixel = markers_.size() >= 4;
  set.source = "the live session's camera calibration";
  for (const CapturedMarker& c : markers_) {
    if (!c.uv)
      return Error{"camera calibration: " + c.name + " has no pixel (click it in the view)"};
    Marker m;
    m.name = c.name;
    m.p_W = c.p_W;
    if (set.by_pixel) {
      m.uv = *c.uv;
    } else {
      // The paper's measurement in camera coordinates: the click's ray, at the measured range.
      m.p_C = present_.unproject_camera(*c.uv, 1.0).normalized() * c.range_m;
    }
    set.markers.push_back(m);
  }
  return set;
}

Result<MarkerCalibration::Solution> MarkerCalibration::solve() const {
  auto set = marker_set();
  if (!set) return set.error();
  auto r = calibrate_extrinsics(present_.intrinsics(), *set);
  if (!r) return Error{"camera calibration: " + r.error().message};
  Solution s{Camera(present_.intrinsics(), r->X_CW), *r, 0, 0};
  s.moved_m = (s.camera.X_WC().p - present_.X_WC().p).norm();
  s.turned_deg = present_.X_CW().R.angularDistance(r->X_CW.R) * 180.0 / units::kPi;
  return s;
}

std::string MarkerCalibration::markers_yaml() const {
  std::ostringstream o;
  o.precision(6);
  o << std::fixed;
  o << "# Markers measured with the " << measured_with_
    << " in the live session (world from the strings,\n"
       "# pixel clicked in the camera view"
    << (markers_.size() == 3 ? ", camera = ray through the pixel at the measured range" : "")
    << "). For: spidar-mr calibrate-camera --markers FILE\nmarkers:\n";
  auto set = marker_set();
  for (std::size_t i = 0; i < markers_.size(); ++i) {
    const CapturedMarker& m = markers_[i];
    o << "  - name: " << m.name << "\n    world: [" << m.p_W.x() << ", " << m.p_W.y() << ", "
      << m.p_W.z() << "]\n";
    if (set && set->by_pixel) {
      o << "    pixel: [" << m.uv->x() << ", " << m.uv->y() << "]\n";
    } else if (set) {
      const Vec3& c = *set->markers[i].p_C;
      o << "    camera: [" << c.x() << ", " << c.y() << ", " << c.z() << "]\n";
    }
  }
  return o.str();
}

}  // namespace spidar::vision
