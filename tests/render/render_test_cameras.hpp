#pragma once
// Cameras the render tests share.
#include "spidar/vision/camera.hpp"

namespace spidar::render::testing {

/// An odd camera: non-square pixels, an off-centre principal point, odd image sizes, looking
/// down at the origin from the front right.
inline vision::Camera odd_camera() {
  vision::Intrinsics K;
  K.fx = 500;
  K.fy = 520;
  K.cx = 150.2;
  K.cy = 110.7;
  K.width = 321;
  K.height = 243;
  return vision::Camera(K, vision::look_at(Vec3(0.1, -0.3, 0.25), Vec3(0.01, 0.02, 0.0)));
}

}  // namespace spidar::render::testing
