#pragma once
/// The Rubik's cube's layer locks (internal to the physics module).
///
/// Every cubelet has a weld `lock_<cubelet>` (body1 = the core, body2 = the cubelet). While the
/// cube is locked, all welds hold the cubelets to the core at their current click: the cube is
/// one rigid body however it is squeezed. After each step the external torque twisting each layer
/// against the rest is measured from the contact forces and applied forces on the cubelets:
///
///   twist_f = τ_layer − (9 / 26) τ_all      (about face f's outward axis through the centre),
///
/// the part of the torque on the layer that its locks must carry (τ_all spread over the 26
/// cubelets by mass would move the cube rigidly). While a layer turns, the layers across it count
/// only their pieces outside it (6 of 9, and 6 / 26 of τ_all): the pieces they share ride on the
/// turning layer's centre, so a hand turning that layer does not twist the layers across it.
/// When |twist_f| exceeds the breakaway torque for the breakaway time (and `dominance` times every
/// other layer's), layer f unlocks: its centre's weld is switched off (the centre turns on its
/// hinge, with the detent) and the other eight cubelets of the layer are welded to the centre
/// instead of the core. When the layer rests near a click, twisted less than
/// the breakaway torque, for the settle time, all nine lock to the core again at the exact click.
/// Only one layer turns at a time: while one is unlocked but lies within 10° of a click (say a
/// grasp holds it a little off it), another layer twisted past the breakaway for the breakaway
/// time takes over, and the first locks at its nearest click.
#include <array>
#include <memory>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/physics/rubiks_cube.hpp"

struct mjModel_;
struct mjData_;

namespace spidar::physics {

class LayerLocks {
 public:
  struct Piece {
    int body = -1;
    int eq = -1;          ///< its lock weld
    int centre_of = -1;   ///< face index (U D F B R L) if it is that face's centre, else −1
  };
  /// nullptr if the scene's cubelets have no `lock_<cubelet>` welds (the older contact-only
  /// mechanism then applies).
  static std::shared_ptr<LayerLocks> Create(const mjModel_* m, int core_body,
                                            const std::vector<Piece>& pieces,
                                            const DetentParams& params, double pitch);

  /// The post-step hook: measures the twists, unlocks or locks a layer.
  void after_step(mjModel_* m, mjData_* d);
  /// Locks every cubelet to the core where it is now, snapped to the nearest click (after
  /// cubelets were moved by hand, e.g. a scramble).
  void lock_all(mjModel_* m, mjData_* d);
  /// The face whose layer turns now (index into U D F B R L), or −1 when the cube is locked.
  int turning() const { return turning_; }
  /// The last measured twist of each layer [N·m], U D F B R L.
  const std::array<double, 6>& twist() const { return twist_; }
  /// Layers unlocked so far.
  int unlocks() const { return unlocks_; }

 private:
  LayerLocks() = default;
  /// Face-layer membership of a piece from its position in the core frame.
  bool in_layer(const mjData_* d, int piece, int face) const;
  /// Welds piece i to body1 at their present relative pose (snapped to the lattice if asked).
  void weld(mjModel_* m, const mjData_* d, int piece, int body1, bool snap);
  void measure(const mjModel_* m, const mjData_* d);
  void unlock(mjModel_* m, const mjData_* d, int face);
  void lock_turning(mjModel_* m, const mjData_* d);

  int core_ = -1;
  std::vector<Piece> pieces_;
  std::vector<int> piece_of_body_;  ///< body id → piece index or −1
  std::array<int, 6> centre_{};     ///< piece index of each face's centre
  std::array<int, 6> hinge_qpos_{}, hinge_dof_{};
  DetentParams params_;
  double pitch_ = 0.019;
  int turning_ = -1;
  int candidate_ = -1;
  double candidate_s_ = 0, settle_s_ = 0;
  std::array<double, 6> twist_{};
  std::vector<Vec3> tau_;  ///< per piece, reused
  std::vector<char> riding_;  ///< per piece: in the turning layer (measure()), reused
  int unlocks_ = 0;
};

}  // namespace spidar::physics
