// The global decision among the verified peaks' finalists: rivals far apart, near poses that
// widen the covariance, and the family margin, on verifications built with known poses.
#include "matching/global/global_decision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "models/geometry.h"

namespace linetrack {
namespace {

constexpr double kTol = 1e-12;
constexpr double kOutlinePx = 1000.0;  // predicted visible outline of every finalist (pixels)

// A verification whose finalists are (pose, evidence, support), the first accepted when asked;
// the accepted pose's covariance is diag(heading 0.2 deg, 5 cm, 5 cm)^2.
PeakVerification Verification(const std::vector<Explanation>& finalists, bool accepted) {
  PeakVerification v;
  v.result.found = accepted;
  for (const Explanation& e : finalists) {
    Finalist f;
    f.pose = e.pose;
    f.evidence.lines_nats = e.score;
    f.evidence.predicted_px = kOutlinePx;
    f.evidence.covered_px = e.support * kOutlinePx;
    v.result.finalists.push_back(f);
  }
  if (accepted) {
    const Pose3Dof& p = finalists.front().pose;
    v.result.pose.x = p.x;
    v.result.pose.y = p.y;
    v.result.pose.heading = p.heading;
    v.result.covariance = Eigen::Vector3d(std::pow(DegToRad(0.2), 2), 0.0025, 0.0025).asDiagonal();
  } else {
    v.result.reason = "no consistent hypothesis";
  }
  return v;
}

Explanation At(double x, double y, double heading_deg, double score, double support) {
  return {{x, y, DegToRad(heading_deg)}, score, support, -1, false};
}

GlobalResult Decided(const std::vector<PeakVerification>& verifications, int padding = 0) {
  GlobalResult out;
  out.verifications = verifications;
  // Verifications with no finalist: they count among the verified peaks only.
  for (int i = 0; i < padding; ++i)
    out.verifications.push_back(Verification({}, false));
  DecideGlobal(VerificationOptions(), GlobalOptions(), &out);
  return out;
}

TEST(GlobalDecision, FamilyMarginIsTheLocalMarginPlusTheLogOfThePeaks) {
  EXPECT_NEAR(FamilyMargin(4.6, 1), 4.6, kTol);
  EXPECT_NEAR(FamilyMargin(4.6, 24), 4.6 + std::log(24.0), kTol);
  EXPECT_NEAR(FamilyMargin(4.6, 0), 4.6, kTol);
}

TEST(GlobalDecision, AClearBestIsTheAnswer) {
  const GlobalResult r = Decided(
      {Verification({At(2, 3, 10, 60, 0.8)}, true), Verification({At(8, 5, 100, 40, 0.7)}, true)});
  ASSERT_TRUE(r.found) << r.reason;
  EXPECT_FALSE(r.ambiguous);
  EXPECT_NEAR(r.best.pose.x, 2.0, kTol);
}

TEST(GlobalDecision, AFarRivalWithinTheLocalMarginIsAmbiguous) {
  const GlobalResult r = Decided(
      {Verification({At(2, 3, 10, 60, 0.8)}, true), Verification({At(8, 5, 100, 57, 0.3)}, false)});
  EXPECT_FALSE(r.found);
  ASSERT_TRUE(r.ambiguous);
  ASSERT_EQ(r.rivals.size(), 2u);
  EXPECT_NEAR(r.rivals[1].x, 8.0, kTol);
}

// The evidence prefers the first pose by 5 nats, beyond the local margin, but the far rival its
// own verification accepted observes more of its outline: within the family margin of 24 peaks
// (4.6 + ln 24 = 7.8 nats) the two criteria disagree, so the answer is "ambiguous".
TEST(GlobalDecision, AFarAcceptedRivalObservingMoreOfItsOutlineIsAmbiguous) {
  const std::vector<PeakVerification> v = {Verification({At(2, 3, 10, 50, 0.66)}, true),
                                           Verification({At(8, 5, 180, 45, 0.77)}, true)};
  const GlobalResult r = Decided(v, 22);
  EXPECT_FALSE(r.found);
  EXPECT_TRUE(r.ambiguous);
  // Observing less of its outline, the rival leaves the best as the answer.
  const GlobalResult weaker = Decided({v[0], Verification({At(8, 5, 180, 45, 0.62)}, true)}, 22);
  EXPECT_TRUE(weaker.found) << weaker.reason;
  // Not accepted by its own verification, it is no such rival either.
  const GlobalResult unaccepted =
      Decided({v[0], Verification({At(8, 5, 180, 45, 0.77)}, false)}, 22);
  EXPECT_TRUE(unaccepted.found) << unaccepted.reason;
  // Beyond the family margin (with 2 peaks: 4.6 + ln 2 = 5.3 nats; the gap is 5), still
  // ambiguous; with the gap 6, the answer.
  EXPECT_TRUE(Decided(v).ambiguous);
  EXPECT_TRUE(Decided({v[0], Verification({At(8, 5, 180, 44, 0.77)}, true)}).found);
}

// A pose 0.8 m from the best, 2 nats below it, is the same place: the answer is the best with its
// covariance widened by the mixture's second moment, w = exp(-2), d = (0, 0.8, 0).
TEST(GlobalDecision, ANearPoseWidensTheCovarianceInsteadOfMakingItAmbiguous) {
  const GlobalResult r = Decided({Verification({At(2, 3, 10, 60, 0.8)}, true),
                                  Verification({At(2.8, 3, 10, 58, 0.8)}, false)});
  ASSERT_TRUE(r.found) << r.reason;
  const double w = std::exp(-2.0);
  EXPECT_NEAR(r.best.covariance(1, 1), 0.0025 + w * 0.64 / (1.0 + w), 1e-9);
  EXPECT_NEAR(r.best.covariance(2, 2), 0.0025, 1e-9);
  EXPECT_NEAR(r.best.position_sigma_m, std::sqrt(r.best.covariance(1, 1)), 1e-9);
}

TEST(GlobalDecision, NearPosesSpreadBeyondTheObservabilityLimitsGiveNoPose) {
  // Two equal poses 1.4 m apart: sigma about 1 m along x (second moment about the answer).
  const GlobalResult r = Decided({Verification({At(2, 3, 10, 60, 0.8)}, true),
                                  Verification({At(3.4, 3, 10, 60, 0.8)}, false)});
  EXPECT_FALSE(r.found);
  EXPECT_FALSE(r.ambiguous);
}

TEST(GlobalDecision, TheBestAcceptedByAnotherVerificationOfTheSamePoseIsTheAnswer) {
  const GlobalResult r = Decided({Verification({At(2, 3, 10, 60, 0.8)}, false),
                                  Verification({At(2.1, 3, 10, 59.9, 0.8)}, true)});
  EXPECT_TRUE(r.found) << r.reason;
}

TEST(GlobalDecision, APartialExplanationIsWithheld) {
  const GlobalResult r = Decided({Verification({At(2, 3, 10, 60, 0.5)}, true)});
  EXPECT_FALSE(r.found);
  EXPECT_FALSE(r.ambiguous);
  EXPECT_NE(r.reason.find("outline"), std::string::npos);
}

}  // namespace
}  // namespace linetrack
