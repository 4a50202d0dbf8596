#pragma once
/// The model hand's outline in the image and which silhouette pixels each hand must explain: the
/// second direction of the silhouette term (residuals.hpp). The first pulls model points lying
/// outside the real silhouette into it; this one pulls the model toward silhouette pixels that no
/// part of it covers, so that a joint lying anywhere inside the silhouette is no longer free.
///
/// Hand-aware: each sampled silhouette pixel belongs to whichever outline is nearest in the image
/// among both hands and both forearms, drawn at the poses the frame predicts (the previous fits).
/// A pixel nearest a forearm or the other hand, or farther than coverage_max_px from its owner,
/// is no evidence for this hand. The owners are decided once per frame; the fit then decides per
/// linearisation which owned pixels its current pose leaves uncovered.
///
/// The outline: each silhouette bone (residuals.hpp) as a capsule projected to a 2D segment whose
/// radius varies linearly from one end's projected radius to the other's, and the palm as the
/// convex hull of its box's projected corners (hand_shape.hpp's PalmBox). Forearm: a capsule from
/// the wrist joint 0.25 m toward the elbow with the bracelet's radius.
#include <array>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "spidar/core/types.hpp"
#include "spidar/hand/hand_model.hpp"
#include "spidar/registration/registration_params.hpp"
#include "spidar/registration/residuals.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::registration {

/// A projected capsule: segment a → c [px], radius ra at a and rc at c [px].
struct ImageCapsule {
  Vec2 a = Vec2::Zero(), c = Vec2::Zero();
  double ra = 0, rc = 0;
  bool valid = false;  ///< both ends in front of the camera
};

/// One hand's outline in the image.
struct ProjectedHand {
  std::array<ImageCapsule, kSilhouetteBoneCount> bones{};
  /// The palm box's corners in right-hand H coordinates [m] (hand_shape.hpp) and their projections
  /// [px]; `hull` lists corner indices of the projected convex hull, counter-clockwise in the
  /// image's (x right, y down) coordinates.
  std::array<Vec3, 8> palm_H = zeros<Vec3, 8>();
  std::array<Vec2, 8> palm_px = zeros<Vec2, 8>();
  std::array<int, 8> hull{};
  int hull_count = 0;  ///< 0 = the palm is not drawn (a corner behind the camera)
  ImageCapsule forearm;
};

/// Draws hand `model` at pose `q` seen by `camera`. `forearm_radius_m` for the forearm capsule,
/// which runs from the wrist along `forearm_H` (right-hand H coordinates, unit; in line with the
/// hand by default, HandObservation::forearm_H).
void project_hand(const hand::HandModel& model, const hand::HandParams& q,
                  const vision::Camera& camera, double forearm_radius_m, ProjectedHand* out,
                  const Vec3& forearm_H = Vec3(0.0, -1.0, 0.0));

/// The nearest part of an outline to pixel `px`.
struct OutlineNearest {
  /// Distance from `px` to the part's edge [px]; ≤ 0 inside it. +∞ when nothing is drawn.
  double distance_px = 0;
  int bone = -1;   ///< silhouette bone (0..18), or −1 for the palm
  double t = 0;    ///< bone: along the segment (0 at a, 1 at c)
  Vec2 edge_px = Vec2::Zero();  ///< the nearest point on the part's edge [px]
  Vec3 palm_H = Vec3::Zero();   ///< palm: that edge point on the box, right-hand H [m]
};

/// The nearest bone capsule or palm edge to `px` (the forearm is not part of the hand).
OutlineNearest nearest_part(const ProjectedHand& hand, const Vec2& px);

/// Distance from `px` to one part's edge [px], ≤ 0 inside: bone 0..18, or −1 for the palm hull.
/// +∞ if that part is not drawn.
double part_distance(const ProjectedHand& hand, int part, const Vec2& px);

/// How far the two edges of a digit's section (digit_sections, residuals.hpp) lie outside every
/// other part of the hand's outline [px]: the smaller of the edges' distances to the nearest part
/// other than the section's own bone (the palm included). Below 0 an edge lies inside another
/// part, whose outline in the image may be the silhouette's edge there (a neighbouring finger seen
/// partly behind this one, the next phalanx's rounded end at a bent joint): the section is then no
/// measurement of this digit alone. +∞ when no other part is drawn.
double section_clearance_px(const ProjectedHand& hand, const DigitAxisPoint& section);

/// A silhouette pixel a hand owns, with the part of the hand nearest to it when its owner was
/// decided (a hint: a pose a little later most likely still covers the pixel with that part).
struct OwnedPixel {
  Vec2 px = Vec2::Zero();  ///< [px]
  int part = -1;           ///< bone 0..18 or −1 (palm)
};

/// Distance from `px` to capsule `c`'s edge [px]; ≤ 0 inside, +∞ if not valid. `t` (optional)
/// receives the parameter of the nearest axis point.
double capsule_distance(const ImageCapsule& c, const Vec2& px, double* t = nullptr);

/// The silhouette pixels each hand owns (see the file comment), sampled on a grid of
/// `params.coverage_stride_px` [px]: `silhouette` is CV_8UC1, non-zero = hand. `hands[h]` null =
/// hand h is not drawn (owns nothing, takes nothing). Reuses the vectors' storage.
void coverage_evidence(const cv::Mat& silhouette, const std::array<const ProjectedHand*, 2>& hands,
                       const RegistrationParams& params, std::array<std::vector<OwnedPixel>, 2>* owned);

}  // namespace spidar::registration
