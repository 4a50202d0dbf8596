#pragma once
/// The Rubik's cube of scenes/rubiks_cube.xml, as a game: the detent that makes a layer click
/// into place every 90°, the logical state read from the cubelets' poses, scrambling and
/// `is_solved()`.
///
/// Faces: U (+z) white, D (−z) yellow, F (−y) green, B (+y) blue, R (+x) red, L (−x) orange, in
/// the cube's own (core) frame. Facelets are listed face by face in the order U R F D L B, 9 per
/// face, each the letter of the face whose colour the sticker has.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/physics/world.hpp"

namespace spidar::physics {

struct DetentParams {
  double stiffness = 0.004;  ///< peak detent torque [N·m]: τ = −k sin(4θ) on each face hinge
  double damping = 0.0;      ///< extra hinge damping [N·m·s/rad]
};

class RubiksCube {
 public:
  /// Finds the cube in the world (bodies `cube`, `cubelet_XYZ`, hinges `hinge_cubelet_XYZ`) and
  /// installs the detent. Fails, naming what is missing, if the scene has no such cube.
  static Result<RubiksCube> Attach(World& world, const DetentParams& detent = {});

  /// Angle of a face's centre hinge [rad] (faces: U D F B R L), unwrapped since the start.
  double face_angle(char face) const;
  /// The same reduced to (−45°, 45°]: how far the layer is from its nearest click.
  double face_misalignment(char face) const;
  /// Pose of the cube core in world.
  Pose core_pose() const;

  /// 54 facelet colours, faces in order U R F D L B.
  std::string facelets() const;
  bool is_solved() const;

  /// Turns a face layer by quarter turns at once (positive: counter-clockwise seen from outside
  /// the face), as a scramble does; the world is re-evaluated.
  Status turn(char face, int quarter_turns);
  /// n random quarter turns; returns them in Singmaster notation (e.g. "U R' F2 …").
  std::string scramble(int n, std::uint64_t seed);

 private:
  struct Cubelet {
    int body = -1;
    int qpos = -1;   ///< joint qpos address
    bool hinge = false;
    std::vector<std::pair<int, char>> stickers;  ///< geom id, face letter of its colour
  };
  RubiksCube() = default;
  Vec3 in_core(const Vec3& p_W) const;

  World* world_ = nullptr;
  int core_ = -1;
  std::vector<Cubelet> cubelets_;
  std::array<int, 6> face_hinge_qpos_{};  ///< U D F B R L
  double pitch_ = 0.019;
};

}  // namespace spidar::physics
