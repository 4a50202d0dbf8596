#include "spidar/render/hand_shapes.hpp"

namespace spidar::render {

Shape capsule_shape(const Vec3& p_W_a, const Vec3& p_W_b, double radius) {
  Shape s;
  s.type = Shape::Type::kCapsule;
  const Vec3 d = p_W_b - p_W_a;
  const double len = d.norm();
  s.X_WS.p = 0.5 * (p_W_a + p_W_b);
  s.X_WS.R = len > 1e-12 ? Quat::FromTwoVectors(Vec3::UnitZ(), d / len) : Quat::Identity();
  s.size = Vec3(radius, 0.5 * len, 0.0);
  return s;
}

void append_hand_shapes(const hand::HandRenderShapes& shapes, SceneSnapshot* scene,
                        const std::array<float, 4>& rgba) {
  const int hand = static_cast<int>(shapes.side);
  for (const hand::Capsule& c : shapes.capsules) {
    Shape s = capsule_shape(c.p_W_a, c.p_W_b, c.radius);
    s.rgba = rgba;
    s.hand = hand;
    s.finger = c.finger;
    scene->shapes.push_back(s);
  }
  for (const hand::Box& b : shapes.boxes) {
    Shape s;
    s.type = Shape::Type::kBox;
    s.X_WS = b.X_WB;
    s.size = b.half_extents;
    s.rgba = rgba;
    s.hand = hand;
    s.finger = -1;
    scene->shapes.push_back(s);
  }
}

}  // namespace spidar::render
