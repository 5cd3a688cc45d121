// Verification of hypotheses on synthetic scenes of the hall: the first-order pose without one
// pair (DeletedPose) against a refit, the per-pair outlier test (OutlyingPair) on true pairs and
// on a wrong pair hidden among them, the leave-one-out rivals of a well-determined pose, and the
// consensus memo (TrimHypothesis gives the same result with and without it); the pose without a
// group of pairs (DeletedGroupPose) against a refit, and the covariance averaged over unreported
// pairs (DoubtedCovariance).
#include "matching/verification.h"

#include <gtest/gtest.h>

#include <numeric>

#include <Eigen/Eigenvalues>

#include "matching/hypothesis_trimming.h"
#include "matching/pose_decision.h"
#include "matching/unreported_doubt.h"
#include "models/synth/synthetic_scenes.h"

namespace linetrack {
namespace {

constexpr int kScenes = 12;
// The first-order deleted pose agrees with a Levenberg-Marquardt refit without the pair within
// this share of the shift, plus a floor for the refit's own convergence.
constexpr double kDeletedShareOfShift = 0.25;
constexpr double kDeletedFloorM = 0.01;
constexpr double kDeletedFloorDeg = 0.05;
// The first-order covariance without a group agrees with the refit's within this share (standard
// deviations of heading and of the position along x and y).
constexpr double kDeletedSigmaShare = 0.15;
// A true pair's posterior at or below this counts as lost (judged outside the frame or gates).
constexpr double kLostTrueGroup = 0.0;
// Summed doubt (1 - p) over the 510 true groups of TrueGroupsKeepAPosterior...'s scenes: 18.0 when
// a rival line that another pair holds is priced as that pair undone, 21.4 when it is free.
constexpr double kMaxTrueGroupsDoubt = 19.5;

// The scenes' lines: exact projections, or with the paper's noise (and calibration error).
enum class SceneNoise { kExact, kPaper };

class VerificationTest : public ::testing::Test {
 protected:
  VerificationTest()
      : model_(WireframeModel::Load(std::string(LINETRACK_SOURCE_DIR) + "/models/hall.cao")),
        area_(NavigableArea::FromModel(model_)) {
    std::vector<int> ids(model_.edges().size());
    std::iota(ids.begin(), ids.end(), 0);
    edges_ = PrepareEdges(model_, ids);  // index = edge id
    options_.refinement.focal_prior_sigma = noise_.focal_relative;
  }

  std::vector<SyntheticScene> Scenes(uint64_t seed, SceneNoise noise) const {
    SyntheticSceneOptions options;
    options.seed = seed;
    options.count = kScenes;
    if (noise == SceneNoise::kExact) {
      options.calibration_sigma = options.angle_sigma = options.offset_sigma_px = 0.0;
    }
    return GenerateScenes(model_, area_, options);
  }

  // The context of a scene (no prior, no occlusion: every pose is plausible where it is).
  VerificationContext Context(const SyntheticScene& scene) {
    camera_ = PaperSyntheticCamera().Undistorted();
    lines_ = PrepareLines(scene.lines, camera_, scene.tilt, noise_, 3.5);
    VerificationContext context;
    context.edges = &edges_;
    context.lines = &lines_;
    context.camera = &camera_;
    context.height = scene.height;
    context.tilt = scene.tilt;
    context.noise = noise_;
    return context;
  }

  WireframeModel model_;
  NavigableArea area_;
  std::vector<MatchEdge> edges_;
  std::vector<ObservedLine> lines_;
  CameraIntrinsics camera_;
  LineNoise noise_;
  VerificationOptions options_;
};

TEST_F(VerificationTest, DeletedPoseMatchesARefitWithoutThePair) {
  int compared = 0;
  for (const SyntheticScene& scene : Scenes(21, SceneNoise::kPaper)) {
    const VerificationContext context = Context(scene);
    const VerifiedPose full =
        RefineHypothesis(context, scene.matches, {scene.truth.Planar()}, options_);
    for (size_t i = 0; i < full.pairs.size(); ++i) {
      Pose3Dof deleted;
      if (!DeletedPose(context, full, i, &deleted)) continue;
      std::vector<std::pair<int, int>> others = full.pairs;
      others.erase(others.begin() + static_cast<long>(i));
      const Pose3Dof refit = RefineHypothesis(context, others, {full.pose}, options_).pose;
      const double shift_m = std::hypot(refit.x - full.pose.x, refit.y - full.pose.y);
      const double shift_deg = RadToDeg(std::abs(WrapAngle(refit.heading - full.pose.heading)));
      EXPECT_LE(std::hypot(deleted.x - refit.x, deleted.y - refit.y),
                kDeletedShareOfShift * shift_m + kDeletedFloorM)
          << "scene " << scene.index << " pair " << i;
      EXPECT_LE(RadToDeg(std::abs(WrapAngle(deleted.heading - refit.heading))),
                kDeletedShareOfShift * shift_deg + kDeletedFloorDeg)
          << "scene " << scene.index << " pair " << i;
      ++compared;
    }
  }
  EXPECT_GT(compared, 5 * kScenes);
}

TEST_F(VerificationTest, OutlyingPairFlagsOnlyAWrongPairHiddenAmongTrueOnes) {
  int tested = 0;
  for (const SyntheticScene& scene : Scenes(22, SceneNoise::kExact)) {
    const VerificationContext context = Context(scene);
    const VerifiedPose truth =
        RefineHypothesis(context, scene.matches, {scene.truth.Planar()}, options_);
    EXPECT_EQ(OutlyingPair(context, options_, truth), -1) << "scene " << scene.index;
    // The line of one true pair given to the edge of another (not on the same edge).
    const auto [edge, line] = scene.matches.front();
    const auto other = std::find_if(scene.matches.begin(), scene.matches.end(),
                                    [&](const auto& m) { return m.first != edge; });
    ASSERT_NE(other, scene.matches.end());
    std::vector<std::pair<int, int>> pairs = scene.matches;
    pairs.emplace_back(other->first, line);
    const VerifiedPose wrong = RefineHypothesis(context, pairs, {scene.truth.Planar()}, options_);
    EXPECT_EQ(OutlyingPair(context, options_, wrong), static_cast<int>(pairs.size()) - 1)
        << "scene " << scene.index;
    ++tested;
  }
  EXPECT_EQ(tested, kScenes);
}

TEST_F(VerificationTest, AWellDeterminedPoseHasNoLeaveOneOutRival) {
  int tested = 0;
  for (const SyntheticScene& scene : Scenes(23, SceneNoise::kExact)) {
    const VerificationContext context = Context(scene);
    const VerifiedPose truth =
        Rematch(context, RefineHypothesis(context, scene.matches, {scene.truth.Planar()}, options_),
                options_);
    if (truth.pairs.size() < 6) continue;  // a small hypothesis may hinge on one pair
    EXPECT_TRUE(LeaveOneOutRivals(context, options_, truth).empty()) << "scene " << scene.index;
    ++tested;
  }
  EXPECT_GE(tested, kScenes / 3);
}

TEST_F(VerificationTest, ConsensusMemoGivesTheSameTrimmedHypothesis) {
  int restarted = 0;
  for (const SyntheticScene& scene : Scenes(24, SceneNoise::kPaper)) {
    VerificationContext context = Context(scene);
    // True pairs plus two lines given to the edges of other pairs: the restart's consensus runs.
    std::vector<std::pair<int, int>> pairs = scene.matches;
    for (size_t k = 0; k + 1 < scene.matches.size() && k < 2; ++k) {
      if (scene.matches[k].first != scene.matches[k + 1].first)
        pairs.emplace_back(scene.matches[k + 1].first, scene.matches[k].second);
    }
    const VerifiedPose start = RefineHypothesis(context, pairs, {scene.truth.Planar()}, options_);
    if (!ConsistentHypothesis(start, options_)) ++restarted;
    VerifiedPose plain = start;
    const bool plain_ok = TrimHypothesis(context, options_, &plain);
    ConsensusMemo memo;
    for (int pass = 0; pass < 2; ++pass) {  // the memo filled, then read
      VerifiedPose memoised = start;
      EXPECT_EQ(TrimHypothesis(context, options_, &memoised, &memo), plain_ok)
          << "scene " << scene.index;
      EXPECT_EQ(memoised.pairs, plain.pairs) << "scene " << scene.index;
      EXPECT_EQ(memoised.pose.x, plain.pose.x) << "scene " << scene.index;
      EXPECT_EQ(memoised.pose.y, plain.pose.y) << "scene " << scene.index;
      EXPECT_EQ(memoised.pose.heading, plain.pose.heading) << "scene " << scene.index;
    }
    if (!ConsistentHypothesis(start, options_)) {
      EXPECT_FALSE(memo.entries.empty()) << "scene " << scene.index;
    }
  }
  EXPECT_GE(restarted, kScenes / 2);
}

// Sibling leaves trimmed to the same pairs are verified once when their refined poses agree
// (SameRefinedPose): the true pairs refined from the truth and from a start 0.3 m and 3 degrees
// off converge to one pose within its tolerance; poses just beyond it are distinct.
TEST_F(VerificationTest, SameRefinedPoseFromDistantStarts) {
  constexpr double kStartOffsetM = 0.3;
  constexpr double kStartOffsetDeg = 3.0;
  for (const SyntheticScene& scene : Scenes(23, SceneNoise::kPaper)) {
    const VerificationContext context = Context(scene);
    const Pose3Dof truth = scene.truth.Planar();
    const Pose3Dof moved{truth.x + kStartOffsetM, truth.y - kStartOffsetM,
                         truth.heading + DegToRad(kStartOffsetDeg)};
    const VerifiedPose a = RefineHypothesis(context, scene.matches, {truth}, options_);
    const VerifiedPose b = RefineHypothesis(context, scene.matches, {moved}, options_);
    EXPECT_TRUE(SameRefinedPose(a.pose, a.refinement.focal_scale, b.pose, b.refinement.focal_scale))
        << "scene " << scene.index << ": " << a.pose.x - b.pose.x << " m, "
        << RadToDeg(a.pose.heading - b.pose.heading) << " deg";
    const double s = a.refinement.focal_scale;
    EXPECT_FALSE(SameRefinedPose(a.pose, s, {a.pose.x + 0.011, a.pose.y, a.pose.heading}, s));
    EXPECT_FALSE(SameRefinedPose(a.pose, s, {a.pose.x, a.pose.y - 0.011, a.pose.heading}, s));
    EXPECT_FALSE(
        SameRefinedPose(a.pose, s, {a.pose.x, a.pose.y, a.pose.heading + DegToRad(0.11)}, s));
    EXPECT_FALSE(SameRefinedPose(a.pose, s, a.pose, s + 0.0011));
  }
}

// DeletedGroupPose on groups of two pairs (the first-order pose without both, Woodbury with a
// 4 x 4 block) against a Levenberg-Marquardt refit without them: pose and standard deviations.
TEST_F(VerificationTest, DeletedGroupPoseMatchesARefitWithoutTheGroup) {
  int compared = 0;
  for (const SyntheticScene& scene : Scenes(25, SceneNoise::kPaper)) {
    const VerificationContext context = Context(scene);
    const VerifiedPose full =
        RefineHypothesis(context, scene.matches, {scene.truth.Planar()}, options_);
    for (size_t i = 0; i + 1 < full.pairs.size(); i += 2) {
      Eigen::Vector4d shift;
      Eigen::Matrix4d covariance;
      if (!DeletedGroupPose(context, full, {i, i + 1}, Eigen::Matrix4d::Zero(), &shift,
                            &covariance)) {
        continue;
      }
      std::vector<std::pair<int, int>> others = full.pairs;
      others.erase(others.begin() + static_cast<long>(i),
                   others.begin() + static_cast<long>(i + 2));
      const VerifiedPose refit = RefineHypothesis(context, others, {full.pose}, options_);
      if (!(refit.refinement.position_sigma_m < 0.5)) continue;  // left unobservable
      const double shift_m = std::hypot(refit.pose.x - full.pose.x, refit.pose.y - full.pose.y);
      const double shift_deg =
          RadToDeg(std::abs(WrapAngle(refit.pose.heading - full.pose.heading)));
      EXPECT_LE(
          std::hypot(full.pose.x + shift(1) - refit.pose.x, full.pose.y + shift(2) - refit.pose.y),
          kDeletedShareOfShift * shift_m + kDeletedFloorM)
          << "scene " << scene.index << " pairs " << i << ", " << i + 1;
      EXPECT_LE(RadToDeg(std::abs(WrapAngle(full.pose.heading + shift(0) - refit.pose.heading))),
                kDeletedShareOfShift * shift_deg + kDeletedFloorDeg)
          << "scene " << scene.index << " pairs " << i << ", " << i + 1;
      for (int k = 0; k < 3; ++k) {
        const double expected = std::sqrt(refit.refinement.covariance(k, k));
        EXPECT_NEAR(std::sqrt(covariance(k, k)), expected, kDeletedSigmaShare * expected)
            << "scene " << scene.index << " pairs " << i << ", " << i + 1 << " axis " << k;
      }
      ++compared;
    }
  }
  EXPECT_GT(compared, 2 * kScenes);
}

// The bound of the prior: removing a group never narrows the pose (C' - C positive
// semi-definite) and the increase stays within the prior's variances (radius^2 / 4, width^2 /
// 12), also for a group that alone fixes a direction (the unbounded deletion fails).
TEST_F(VerificationTest, DeletedGroupPoseBoundedByThePriorWidensWithinIt) {
  PriorRegion prior;
  prior.radius = 0.3;
  prior.heading = {-DegToRad(5.0), DegToRad(5.0)};
  const Eigen::Matrix4d information = PriorInformation(prior);
  int bounded = 0;
  for (const SyntheticScene& scene : Scenes(26, SceneNoise::kExact)) {
    const VerificationContext context = Context(scene);
    const VerifiedPose full =
        RefineHypothesis(context, scene.matches, {scene.truth.Planar()}, options_);
    // Groups: each pair alone, and every pair but two (the pose then rests on two lines).
    std::vector<std::vector<size_t>> groups;
    std::vector<size_t> most;
    for (size_t i = 0; i < full.pairs.size(); ++i) {
      groups.push_back({i});
      if (i >= 2) most.push_back(i);
    }
    groups.push_back(most);
    for (const std::vector<size_t>& group : groups) {
      Eigen::Vector4d shift, free_shift;
      Eigen::Matrix4d covariance, free_covariance;
      ASSERT_TRUE(DeletedGroupPose(context, full, group, information, &shift, &covariance))
          << "scene " << scene.index;
      const Eigen::Matrix4d increase = covariance - full.refinement.covariance;
      EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(increase).eigenvalues().minCoeff(),
                -1e-9 * full.refinement.covariance.norm())
          << "scene " << scene.index;
      // (A - J'J)^-1 <= P^-1 when the information left, C^-1 - J'J, is positive semi-definite.
      const Eigen::Matrix4d prior_covariance =
          Eigen::Vector4d(information(0, 0) > 0.0 ? 1.0 / information(0, 0) : 0.0,
                          1.0 / information(1, 1), 1.0 / information(2, 2), 0.0)
              .asDiagonal();
      for (int k = 0; k < 3; ++k) {
        EXPECT_LE(covariance(k, k),
                  (full.refinement.covariance(k, k) + prior_covariance(k, k)) * (1.0 + 1e-6))
            << "scene " << scene.index << " axis " << k;
      }
      if (!DeletedGroupPose(context, full, group, Eigen::Matrix4d::Zero(), &free_shift,
                            &free_covariance)) {
        ++bounded;
      }
    }
  }
  EXPECT_GT(bounded, 0);
}

// DoubtedCovariance: nothing to doubt when every pair is reported; otherwise at least the pose's
// own covariance.
TEST_F(VerificationTest, DoubtedCovarianceWidensOnlyOverUnreportedPairs) {
  for (const SyntheticScene& scene : Scenes(27, SceneNoise::kPaper)) {
    const VerificationContext context = Context(scene);
    const VerifiedPose full =
        RefineHypothesis(context, scene.matches, {scene.truth.Planar()}, options_);
    EXPECT_EQ(DoubtedCovariance(context, options_, full, full.pairs), full.refinement.covariance)
        << "scene " << scene.index;
    std::vector<DoubtedGroup> groups;
    const Eigen::Matrix4d doubted = DoubtedCovariance(context, options_, full, {}, &groups);
    EXPECT_FALSE(groups.empty()) << "scene " << scene.index;
    EXPECT_GE(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(doubted - full.refinement.covariance)
                  .eigenvalues()
                  .minCoeff(),
              -1e-9 * doubted.norm())
        << "scene " << scene.index;
    for (const DoubtedGroup& group : groups) {
      EXPECT_GE(group.probability_true, 0.0);
      EXPECT_LE(group.probability_true, 1.0);
    }
  }
}

// The posterior of a true group is judged by the others' pose, but which edges are in view, over
// which stretch, from the pose where the pairs were found: a small shift must not push a true
// edge out of the frame or leave its line overhanging a projection clipped at the border (which
// would give a true pair p = 0); and a rival line that another true pair holds is
// not a free explanation (the summed doubt of true groups stays below kMaxTrueGroupsDoubt).
TEST_F(VerificationTest, TrueGroupsKeepAPosteriorAtTheImageBorder) {
  int groups = 0, lost = 0;
  double true_doubt = 0.0;
  for (const uint64_t seed : {31, 32, 33, 34, 35, 36}) {
    for (const SyntheticScene& scene : Scenes(seed, SceneNoise::kPaper)) {
      const VerificationContext context = Context(scene);
      // The pairs guided matching finds from the truth's pairs (as an answer's interpretation).
      const VerifiedPose found =
          VerifyHypothesis(context, scene.matches, {scene.truth.Planar()}, options_);
      std::vector<DoubtedGroup> doubted;
      DoubtedCovariance(context, options_, found, {}, &doubted);
      for (const DoubtedGroup& group : doubted) {
        const bool true_group =
            std::all_of(group.pairs.begin(), group.pairs.end(), [&](const auto& pair) {
              return std::find(scene.matches.begin(), scene.matches.end(), pair) !=
                     scene.matches.end();
            });
        if (!true_group) continue;
        true_doubt += 1.0 - group.probability_true;
        ++groups;
        if (group.probability_true <= kLostTrueGroup) {
          ++lost;
          ADD_FAILURE() << "seed " << seed << " scene " << scene.index << " edge "
                        << group.pairs.front().first << ": p " << group.probability_true;
        }
      }
    }
  }
  EXPECT_GT(groups, 100);
  EXPECT_EQ(lost, 0);
  EXPECT_LE(true_doubt, kMaxTrueGroupsDoubt);
}

}  // namespace
}  // namespace linetrack
