#include "spidar/sim/model_ceiling.hpp"

#include <opencv2/core.hpp>

#include "spidar/registration/metrics.hpp"
#include "spidar/render/renderer.hpp"

namespace spidar::sim {

struct ModelCeiling::Impl {
  vision::Camera camera;
  std::array<hand::HandModel, 2> user;
  render::HandSkinParams skin;
  std::array<render::HandSkin, 2> skins;
  std::shared_ptr<const std::vector<MeshData>> meshes;
  std::unique_ptr<render::Renderer> renderer;
  SceneSnapshot scene;
  render::RenderTargets targets;
  cv::Mat model_mask;
};

ModelCeiling::ModelCeiling(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
ModelCeiling::~ModelCeiling() = default;

Result<std::unique_ptr<ModelCeiling>> ModelCeiling::create(render::Context& context,
                                                           const vision::Camera& camera,
                                                           const std::array<hand::HandModel, 2>& user,
                                                           const render::HandSkinParams& model_skin) {
  if (user[0].side != hand::Side::kLeft || user[1].side != hand::Side::kRight)
    return Error{"model ceiling: hands must be {left, right}"};
  if (auto st = render::validate(model_skin); !st) return Error{"model ceiling: " + st.error().message};
  auto impl = std::make_unique<Impl>();
  impl->camera = camera;
  impl->user = user;
  impl->skin = model_skin;
  auto meshes = std::make_shared<std::vector<MeshData>>();
  for (int h = 0; h < 2; ++h) impl->skins[h] = render::build_hand_skin(user[h], model_skin, meshes.get());
  impl->meshes = std::move(meshes);
  auto r = render::Renderer::create(context, camera.width(), camera.height());
  if (!r) return r.error();
  impl->renderer = std::move(r).value();
  return std::unique_ptr<ModelCeiling>(new ModelCeiling(std::move(impl)));
}

Result<double> ModelCeiling::iou(const std::array<hand::HandParams, 2>& truth,
                                 const cv::Mat& real_hand_only,
                                 const std::array<std::optional<Vec3>, 2>& toward_elbow_W,
                                 const cv::Mat& real_hand_id, SilhouetteLoss* loss) {
  Impl& s = *impl_;
  if (real_hand_only.type() != CV_8UC1 || real_hand_only.cols != s.camera.width() ||
      real_hand_only.rows != s.camera.height())
    return Error{"model ceiling: expected a CV_8UC1 mask of the camera's size"};
  s.scene.shapes.clear();
  s.scene.meshes = s.meshes;
  for (const auto& d : toward_elbow_W)
    if (d && !(d->allFinite() && std::abs(d->norm() - 1.0) < 1e-6))
      return Error{"model ceiling: a forearm direction must be a finite unit vector"};
  for (std::size_t h = 0; h < 2; ++h) {
    const auto& d = toward_elbow_W[h];
    render::pose_hand_skin(s.user[h], s.skins[h], truth[h], s.skin, &s.scene, d ? &*d : nullptr);
  }
  render::RenderParams rp;
  rp.hands = render::HandDrawMode::kHidden;
  if (auto st = s.renderer->render(s.scene, s.camera, rp); !st) return st.error();
  if (auto st = s.renderer->read(&s.targets, render::kHandId); !st) return st.error();
  // The model's palms and digits (its forearm and bracelet, if drawn, are not the hand).
  s.model_mask.create(s.targets.hand_id.size(), CV_8UC1);
  for (int y = 0; y < s.model_mask.rows; ++y) {
    const std::uint8_t* id = s.targets.hand_id.ptr<std::uint8_t>(y);
    std::uint8_t* o = s.model_mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < s.model_mask.cols; ++x) {
      o[x] = is_hand_pixel(id[x]) ? 255 : 0;
    }
  }
  if (loss != nullptr)
    if (auto st = silhouette_loss(s.targets.hand_id, real_hand_id, loss); !st)
      return Error{"model ceiling: " + st.error().message};
  return registration::mask_iou(s.model_mask, real_hand_only);
}

}  // namespace spidar::sim
