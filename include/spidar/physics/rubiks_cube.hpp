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
#include <memory>
#include <string>
#include <vector>

#include "spidar/core/result.hpp"
#include "spidar/physics/world.hpp"

namespace spidar::physics {

class LayerLocks;

struct DetentParams {
  double stiffness = 0.02;   ///< peak detent torque [N·m]: τ = −k sin(4θ) on each face hinge
  double damping = 0.0;      ///< extra hinge damping [N·m·s/rad]
  /// Layer locks (scenes whose cubelets have `lock_<cubelet>` welds, as scenes/rubiks_cube.xml):
  /// the cube is rigid until the external torque twisting one layer against the rest exceeds
  /// this for `breakaway_time_s`; that layer then turns on its hinge until it rests within
  /// `lock_tolerance_rad` of a click for `settle_time_s` and locks again. Like a real cube's
  /// internal friction, it keeps a firm grasp from twisting faces.
  /// [N·m]: a stiff 57 mm cube; above what a firm two-finger pinch at off-centre points puts on a
  /// layer (grasp transients up to ~0.1 N·m seen in the demo), below what a turning hand gives.
  double breakaway_torque = 0.12;
  double breakaway_time_s = 0.03;   ///< [s]: longer than the transients of a closing grasp
  /// A layer breaks away only if twisted this many times harder than any other (one hand turning
  /// one layer, not a jerky grasp twisting several).
  double dominance = 1.5;
  /// Another layer may break away while one is unlocked only if that one lies this near a click
  /// (it then locks there) [rad] (10°).
  double switch_tolerance_rad = 0.17;
  double lock_tolerance_rad = 0.035;  ///< [rad] (2°)
  double settle_time_s = 0.02;      ///< [s]
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
  /// The face whose layer is unlocked and turning now (U D F B R L), or 0 when the cube is locked
  /// rigid (or the scene has no layer locks).
  char turning_face() const;
  /// How often a layer has broken away so far.
  int layer_unlocks() const;
  /// The external torque twisting a face's layer against the rest of the cube, measured in the
  /// last step [N·m] about the face's outward axis (0 without layer locks).
  double layer_twist(char face) const;

  /// 54 facelet colours, faces in order U R F D L B.
  std::string facelets() const;
  bool is_solved() const;

  /// Turns a face layer by quarter turns at once (positive: counter-clockwise seen from outside
  /// the face), as a scramble does; the world is re-evaluated.
  Status turn(char face, int quarter_turns);
  /// Locks every cubelet where it is now, at the nearest click (after the world's state was
  /// reset or set from outside; turn() and scramble() do it themselves).
  void lock_in_place();
  /// n random quarter turns; returns them in Singmaster notation (e.g. "U R' F2 …").
  std::string scramble(int n, std::uint64_t seed);

 private:
  struct Cubelet {
    int body = -1;
    int qpos = -1;   ///< joint qpos address
    bool hinge = false;
    std::vector<std::pair<int, char>> stickers;  ///< geom id, face letter of its colour
    std::string name;
  };
  RubiksCube() = default;
  Vec3 in_core(const Vec3& p_W) const;

  World* world_ = nullptr;
  std::shared_ptr<LayerLocks> locks_;  ///< shared with the world's post-step hook; may be null
  int core_ = -1;
  std::vector<Cubelet> cubelets_;
  std::array<int, 6> face_hinge_qpos_{};  ///< U D F B R L
  double pitch_ = 0.019;
};

}  // namespace spidar::physics
