// A fit with every term on allocates nothing (it runs once per hand per camera frame).
#include <gtest/gtest.h>

#include "allocation_counter.hpp"
#include "registration_test_util.hpp"

namespace spidar::registration {
namespace {

TEST(NoAllocation, FitWithEveryTerm) {
  namespace alloc = ::spidar::testing::allocations;
  if (!alloc::available()) GTEST_SKIP() << "allocation counting is off under ASan";
  const auto models = test::model_hands();
  const auto truth = test::reaching_hands();
  const vision::Camera camera = vision::default_rig_camera();
  cv::Mat mask;
  for (int h = 0; h < 2; ++h) test::draw_capsule_mask(models[h], truth[h], camera, &mask);
  test::MaskEvidence ev;
  test::evidence_from_mask(mask, &ev);
  RegistrationParams params;
  params.silhouette_term = true;
  params.silhouette_inward = true;
  const auto owned = test::owned_pixels(mask, models, truth, camera, params);
  const SuccessiveAdjustment solver(params);
  std::mt19937 rng(5);
  std::array<HandObservation, 2> obs;
  std::array<hand::HandParams, 2> start;
  for (int h = 0; h < 2; ++h) {
    vision::BraceletObservation b;
    b.found = true;
    b.wrist_px = camera.project(truth[h].p_W_wrist());
    b.confidence = 1.0;
    obs[h] = test::observe(models[h], truth[h], b, rng);
    start[h] = test::perturb(truth[h], models[h], rng);
  }
  alloc::mark_this_thread();
  alloc::start();
  int iterations = 0;
  for (int h = 0; h < 2; ++h) {
    hand::HandParams q = start[h];
    ImageEvidence image = ev.evidence(&camera, true);
    image.coverage = &owned[h];
    iterations += solver.fit(models[h], obs[h], image, &start[h], &q).iterations;
  }
  alloc::stop();
  EXPECT_EQ(alloc::count(), 0);
  EXPECT_GT(iterations, 2);
}

}  // namespace
}  // namespace spidar::registration
