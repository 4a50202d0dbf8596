#pragma once
/// The OpenGL 3.3 core renderer: draws a SceneSnapshot from a vision::Camera into offscreen
/// targets and reads them back.
///
/// Targets (all the camera's image size, rows top to bottom as in the image):
///   colour      the virtual scene, lit (ambient + one directional light fixed to the camera);
///               hand shapes appear in it only with HandDrawMode::kVisible (debugging)
///   depth       z_C of the nearest *non-hand* surface [m] (linear, along the optical axis, not
///               the distance along the ray); +inf where there is none
///   hand_depth  z_C of the nearest hand surface [m]; +inf where there is none
///   hand_id     encode_hand_id() of that nearest hand surface; 0 where there is none
/// A hand is front-most at a pixel where hand_depth < depth. Keeping the hands apart from the
/// scene lets the compositor decide occlusion itself (render/compositor.hpp).
///
/// Shapes whose `hand` ≥ 0 are hands (render/hand_shapes.hpp turns the hand model's capsules
/// into such shapes). Shape conventions are SceneSnapshot's: box half sizes; sphere radius;
/// capsule and cylinder radius and half length along the shape's z; plane half sizes in its
/// x-y plane (0 = 5 m, "infinite"); meshes in the shape frame.
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <opencv2/core/mat.hpp>

#include "spidar/core/result.hpp"
#include "spidar/core/scene_snapshot.hpp"
#include "spidar/render/context.hpp"
#include "spidar/render/gl_camera.hpp"
#include "spidar/vision/camera.hpp"

namespace spidar::render {

/// Hand-id target value of a hand shape: 1 + 8·hand + (finger + 1), hand 0 (left) or 1 (right),
/// finger −1 (palm, wrist) … 6; 0 means "no hand".
constexpr std::uint8_t encode_hand_id(int hand, int finger) {
  const int h = hand < 0 ? 0 : (hand > 1 ? 1 : hand);
  const int f = finger < -1 ? -1 : (finger > 6 ? 6 : finger);
  return static_cast<std::uint8_t>(1 + 8 * h + (f + 1));
}
struct HandId {
  int hand = -1;    ///< −1: no hand
  int finger = -1;  ///< −1: palm/wrist or no hand
};
constexpr HandId decode_hand_id(std::uint8_t id) {
  if (id == 0) return {};
  return {(id - 1) / 8, (id - 1) % 8 - 1};
}

enum class HandDrawMode {
  kHidden,   ///< hands go to hand_depth and hand_id only (the compositor's input)
  kVisible,  ///< also drawn into colour, occluding the scene (debugging)
};

struct RenderParams {
  DepthRange depth_range;
  std::array<float, 3> background_rgb{0.16f, 0.17f, 0.20f};  ///< colour where nothing is drawn
  HandDrawMode hands = HandDrawMode::kHidden;
  /// kVisible: paint every hand in this colour (the default skin tone), or, if
  /// `hands_keep_colour`, in each shape's own rgba.
  std::array<float, 4> visible_hand_rgba{0.85f, 0.62f, 0.50f, 1.f};
  bool hands_keep_colour = false;
  /// Direction toward the light in the camera frame C (x right, y down, z forward); normalised.
  Vec3 light_dir_C{-0.3, -0.7, -0.65};
  float ambient = 0.35f;  ///< fraction of the colour lit without the light
  /// Draw the static world (the primitives of body 0, the physics world body: a table, a frame)
  /// once and copy it into each frame while those shapes, the camera and the light stay the
  /// same. Software GL pays per covered pixel, and a table covers most of the image.
  bool cache_static = true;
};

/// Which targets read() copies back.
enum Target : unsigned {
  kColour = 1u,
  kDepth = 2u,
  kHandDepth = 4u,
  kHandId = 8u,
  kAllTargets = 15u,
};

struct RenderTargets {
  cv::Mat colour;      ///< CV_8UC3, BGR
  cv::Mat depth;       ///< CV_32FC1 [m], +inf: empty
  cv::Mat hand_depth;  ///< CV_32FC1 [m], +inf: no hand
  cv::Mat hand_id;     ///< CV_8UC1, encode_hand_id, 0: no hand
  /// The bounding box of every pixel a hand was drawn at (an empty rectangle: no hand), known when
  /// read() copied hand_id; std::nullopt: not known (a compositor then looks at the whole image).
  std::optional<cv::Rect> hand_box;
};

class Renderer {
 public:
  /// Compiles the shaders and creates targets of the given size in `context` (which must be
  /// current, and outlive the renderer). Error names the failing step (shader log included).
  static Result<std::unique_ptr<Renderer>> create(Context& context, int width = 640,
                                                  int height = 480);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Draws `scene` seen by `camera` into the targets (resized to the camera's image if needed).
  /// Error on invalid params or a GL failure; shapes with non-finite poses are skipped.
  Status render(const SceneSnapshot& scene, const vision::Camera& camera,
                const RenderParams& params = {});
  /// Copies the chosen targets (a Target mask) of the last render() into `out`, reusing its
  /// buffers when their size fits.
  Status read(RenderTargets* out, unsigned targets = kAllTargets) const;

  /// Shows a BGR image (e.g. a composite) in the window of `context`, scaled to fit with its
  /// aspect ratio kept, then swaps buffers. Error for a headless context or a non-8UC3 image.
  Status present(Context& context, const cv::Mat& bgr);

  int width() const;
  int height() const;

 private:
  struct Impl;
  explicit Renderer(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

}  // namespace spidar::render
