// The successive adjustment's optimum against an independent generic solver: Eigen's
// (unsupported) Levenberg-Marquardt with numerical derivatives, on the same cost from the same
// start. Image targets do not move here (fingertips in 3D, the projected wrist, the prior), so
// both minimise one fixed function.
#include <gtest/gtest.h>

#include <unsupported/Eigen/NonLinearOptimization>
#include <unsupported/Eigen/NumericalDiff>

#include "registration_test_util.hpp"
#include "spidar/registration/residuals.hpp"

namespace spidar::registration {
namespace {

struct ResidualFunctor {
  using Scalar = double;
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };

  const ResidualProblem* problem;
  const FrozenTargets* targets;
  int rows;
  int inputs() const { return hand::kParamCount; }
  int values() const { return rows; }
  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& f) const {
    hand::HandParams q;
    q.q = x;
    VecX r;
    stacked_residuals(*problem, *targets, q, &r, nullptr);
    f = r;
    return 0;
  }
};

TEST(GenericSolver, SameOptimumAsEigenLevenbergMarquardt) {
  const auto models = test::model_hands();
  const auto truths = test::truth_models();
  const vision::Camera camera = vision::default_rig_camera();
  for (int side = 0; side < 2; ++side) {
    for (std::uint32_t seed : {11u, 12u, 13u}) {
      std::mt19937 rng(seed);
      // The user's true hand (other proportions than the model) with noisy strings, a wrist
      // pixel off by a few px, and a prior elsewhere: the optimum has a nonzero cost.
      const hand::HandParams truth = test::reaching_hands(static_cast<int>(seed % 2))[side];
      vision::BraceletObservation b;
      b.found = true;
      b.wrist_px = camera.project(truth.p_W_wrist()) + Vec2(2.0, -3.0);
      b.confidence = 0.9;
      const HandObservation obs = test::observe(truths[side], truth, b, rng, 0.001);
      const hand::HandParams prior = test::perturb(truth, models[side], rng, 0.01, 0.1, 0.1);
      const hand::HandParams start = test::perturb(truth, models[side], rng);

      RegistrationParams params;
      params.bracelet_offset_m = 0.0;
      params.bracelet_surface_shift = 0.0;  // the wrist pixel above is the wrist joint's
      params.max_iterations = 200;
      params.cost_epsilon = 0.0;
      params.step_epsilon = 1e-12;
      params.relative_epsilon = 0.0;  // run to the optimum: this test compares optima
      ImageEvidence image;
      image.camera = &camera;  // no matte, no silhouette: only the projected wrist
      const ResidualProblem pr{&models[side], &obs, &image, &prior, &params};

      hand::HandParams ours = start;
      const FitReport rep = SuccessiveAdjustment(params).fit(models[side], obs, image, &prior, &ours);

      FrozenTargets tg;
      freeze_targets(pr, start, &tg);
      ASSERT_TRUE(tg.wrist_active);
      VecX r0;
      stacked_residuals(pr, tg, start, &r0, nullptr);
      ResidualFunctor fn{&pr, &tg, static_cast<int>(r0.size())};
      Eigen::NumericalDiff<ResidualFunctor, Eigen::Central> numdiff(fn);
      Eigen::LevenbergMarquardt<Eigen::NumericalDiff<ResidualFunctor, Eigen::Central>> lm(numdiff);
      lm.parameters.maxfev = 20000;
      lm.parameters.xtol = 1e-14;
      lm.parameters.ftol = 1e-14;
      Eigen::VectorXd x = start.q;
      lm.minimize(x);
      hand::HandParams theirs;
      theirs.q = x;
      const double cost_theirs = term_costs(pr, tg, theirs).total();

      // The optimum is interior (no joint limit active), so the unconstrained solver applies.
      EXPECT_TRUE(hand::within_limits(theirs, models[side].limits)) << "seed " << seed;
      EXPECT_GT(cost_theirs, 1.0);
      EXPECT_LT(rep.cost_final, rep.cost_initial);
      EXPECT_NEAR(rep.cost_final, cost_theirs, 1e-6 * cost_theirs + 1e-9)
          << "side " << side << " seed " << seed << " ours " << rep.cost_final << " after "
          << rep.iterations << " iterations, Eigen " << cost_theirs;
      EXPECT_LT((ours.q - theirs.q).cwiseAbs().maxCoeff(), 1e-4) << "side " << side;
    }
  }
}

}  // namespace
}  // namespace spidar::registration
