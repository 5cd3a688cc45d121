// The decision's steps on hand-made verified poses (their evidence complete, so no scene is
// needed): the ranking's reasons for having no pose, the distinct poses among ranked ones, and
// the ambiguity rule against distinct plausible and unobservable poses.
#include "matching/pose_decision.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace linetrack {
namespace {

// A plausible verified pose at (x, 0) with heading 0 and `nats` of evidence, all from its lines.
VerifiedPose Plausible(double x_m, double nats) {
  VerifiedPose v;
  v.pose = {x_m, 0.0, 0.0};
  v.plausible = true;
  v.evidence.lines_nats = nats;
  v.evidence_complete = true;
  return v;
}

// The same pose, not plausible for `why`; an unobservable one when `why` is one of the two
// reasons a pose inside the prior can still be a rival for.
VerifiedPose Implausible(double x_m, double nats, const std::string& why) {
  VerifiedPose v = Plausible(x_m, nats);
  v.plausible = false;
  v.implausible_because = why;
  v.unobservable = why == "unobservable" || why == "held at the prior's border";
  return v;
}

TEST(PoseDecision, RankingGivesTheReasonWhenNoPoseCanBeAnswered) {
  const VerificationContext context;  // not read: no plausible pose
  const VerificationOptions options;
  std::string why;
  std::vector<VerifiedPose> none;
  EXPECT_FALSE(RankPoses(context, options, &none, &why));
  EXPECT_EQ(why, "no consistent hypothesis");
  std::vector<VerifiedPose> implausible = {Implausible(0.0, 20.0, "too few edges"),
                                           Implausible(1.0, 30.0, "outside the prior")};
  EXPECT_FALSE(RankPoses(context, options, &implausible, &why));
  EXPECT_EQ(why, "no plausible pose (best: outside the prior)");  // the larger evidence first
}

TEST(PoseDecision, DistinctPosesAreTheBestOfEachPose) {
  const VerificationOptions options;  // same pose within 0.5 m and 5 degrees
  const std::vector<VerifiedPose> ranked = {Plausible(0.0, 50.0), Plausible(0.3, 45.0),
                                            Plausible(1.0, 40.0), Plausible(1.2, 39.0),
                                            Implausible(3.0, 38.0, "outside the prior")};
  EXPECT_EQ(DistinctPoses(ranked, options), (std::vector<size_t>{0, 2}));
}

TEST(PoseDecision, TheBestMustBeatEveryDistinctPoseByTheAmbiguityMargin) {
  const VerificationContext context;  // not read: every evidence is complete
  const VerificationOptions options;  // ambiguity_nats 4.6
  std::string why;
  std::vector<VerifiedPose> close = {Plausible(0.0, 50.0), Plausible(1.0, 47.0)};
  EXPECT_FALSE(ClearlyBest(context, options, DistinctPoses(close, options), &close, &why));
  EXPECT_EQ(why, "ambiguous: another pose explains the image almost as well");

  std::vector<VerifiedPose> clear = {Plausible(0.0, 50.0), Plausible(1.0, 40.0),
                                     Implausible(0.2, 49.0, "unobservable")};  // the same pose
  EXPECT_TRUE(ClearlyBest(context, options, DistinctPoses(clear, options), &clear, &why));

  for (const std::string reason : {"unobservable", "held at the prior's border"}) {
    std::vector<VerifiedPose> rival = {Plausible(0.0, 50.0), Implausible(2.0, 47.0, reason)};
    EXPECT_FALSE(ClearlyBest(context, options, DistinctPoses(rival, options), &rival, &why));
    EXPECT_EQ(why, "ambiguous: " +
                       std::string(reason == "unobservable" ? "an unobservable pose"
                                                            : "a pose held at the prior's border") +
                       " explains the image almost as well");
  }
  // A distinct pose that is not a rival for another reason does not count.
  std::vector<VerifiedPose> outside = {Plausible(0.0, 50.0),
                                       Implausible(2.0, 49.0, "outside the prior")};
  EXPECT_TRUE(ClearlyBest(context, options, DistinctPoses(outside, options), &outside, &why));
}

}  // namespace
}  // namespace linetrack
