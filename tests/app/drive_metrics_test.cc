// The figures of `bench drive` on hand-made frames: availability over the observable frames,
// wrong and far-off poses, ATE, the worst frames, recovery after each blackout, replay speed;
// replay's frames.csv read by column names.
#include "app/drive_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "models/errors.h"

namespace linetrack::app {
namespace {

constexpr double kTol = 1e-12;

FrameTruth Truth(long frame, bool observable, bool covered = false) {
  FrameTruth t;
  t.frame = frame;
  t.t = 0.1 * frame;
  t.observable = observable;
  t.covered = covered;
  return t;
}

ReplayedFrame Replayed(long frame, const std::string& status, double step_ms,
                       std::optional<double> error_m = std::nullopt, double error_deg = 0.0) {
  ReplayedFrame f;
  f.frame = frame;
  f.t = 0.1 * frame;
  f.status = status;
  f.step_ms = step_ms;
  f.has_pose = error_m.has_value();
  f.translation_error_m = error_m;
  if (error_m) f.rotation_error_deg = error_deg;
  return f;
}

// Ten frames: 0-3 observable and tracked (one 12 cm off, one 3 deg off), 4-5 covered, 6 not
// observable, 7-9 observable: lost, relocalised 60 cm off, tracking again within bounds.
TEST(DriveMetrics, CountsAgainstTheTruth) {
  std::vector<FrameTruth> truth;
  for (long k = 0; k < 10; ++k)
    truth.push_back(Truth(k, k < 4 || k > 6, k == 4 || k == 5));
  const std::vector<ReplayedFrame> replayed = {Replayed(0, "tracking", 4.0, 0.01, 0.1),
                                               Replayed(1, "tracking", 4.0, 0.12, 0.2),
                                               Replayed(2, "tracking", 2.0, 0.02, 3.0),
                                               Replayed(3, "tracking", 2.0, 0.03, 0.1),
                                               Replayed(4, "lost", 1.0),
                                               Replayed(5, "lost", 1.0),
                                               Replayed(6, "lost", 30.0),
                                               Replayed(7, "lost", 40.0),
                                               Replayed(8, "relocalised", 50.0, 0.6, 1.0),
                                               Replayed(9, "tracking", 4.0, 0.04, 0.5)};
  const DriveMetrics m = ComputeDriveMetrics(truth, replayed, 55.0);
  EXPECT_EQ(m.frames, 10);
  EXPECT_EQ(m.observable, 7);
  EXPECT_EQ(m.observable_with_pose, 6);
  EXPECT_EQ(m.observable_tracking, 5);
  EXPECT_NEAR(m.Availability(), 6.0 / 7.0, kTol);
  EXPECT_NEAR(m.TrackingAvailability(), 5.0 / 7.0, kTol);
  EXPECT_EQ(m.poses, 6);
  EXPECT_EQ(m.poses_unobservable, 0);
  EXPECT_EQ(m.beyond_near, 3);  // 12 cm, 3 deg, 60 cm
  EXPECT_EQ(m.beyond_far, 1);   // 60 cm
  const double squares =
      0.01 * 0.01 + 0.12 * 0.12 + 0.02 * 0.02 + 0.03 * 0.03 + 0.6 * 0.6 + 0.04 * 0.04;
  EXPECT_NEAR(m.ate_m, std::sqrt(squares / 6.0), kTol);
  EXPECT_EQ(m.worst_m_frame, 8);
  EXPECT_EQ(m.worst_deg_frame, 2);
  EXPECT_NEAR(m.worst_deg, 3.0, kTol);
  ASSERT_GE(m.worst_frames.size(), 2u);
  EXPECT_EQ(replayed[m.worst_frames[0]].frame, 8);
  EXPECT_EQ(replayed[m.worst_frames[1]].frame, 1);
  // Recovery: the blackout is frames 4-5; frame 7 is the first observable after it; frame 9 is
  // the first within 10 cm / 2 deg: 2 frames.
  ASSERT_EQ(m.recoveries.size(), 1u);
  EXPECT_EQ(m.recoveries[0].first, 4);
  EXPECT_EQ(m.recoveries[0].last, 5);
  EXPECT_EQ(m.recoveries[0].first_observable, 7);
  EXPECT_EQ(m.recoveries[0].recovered, 9);
  EXPECT_EQ(m.recoveries[0].frames_to_recover, 2);
  // Tracking frames: 0, 1, 2, 3, 9 in 16 ms.
  EXPECT_NEAR(m.tracking_fps, 1000.0 * 5 / 16.0, 1e-9);
  EXPECT_EQ(m.overall_fps, 55.0);
  EXPECT_FALSE(m.integrity_failures.has_value());

  const std::string table = FormatDriveTable({{"tiny", m, 2.4}});
  EXPECT_NE(table.find("| | tiny |"), std::string::npos) << table;
  EXPECT_NE(table.find("| availability: observable frames with a pose | 85.7 % |"),
            std::string::npos)
      << table;
  EXPECT_NE(table.find("| frames to recover after each blackout | 2 |"), std::string::npos);
  EXPECT_NE(table.find("| integrity failures (`tracking` beyond its protection level) | n/a |"),
            std::string::npos);
  EXPECT_NE(FormatWorstFrames(m, truth, replayed).find("| 8 | 0.8 | relocalised | 60.0 cm"),
            std::string::npos);
}

// Coasted poses (source `odometry`): counted apart among the `tracking` ones, and no recovery
// after a blackout: frames 2-3 covered, 4-5 coasted within bounds, 6 an image pose.
TEST(DriveMetrics, CoastedPosesAreCountedApartAndAreNoRecovery) {
  std::vector<FrameTruth> truth;
  for (long k = 0; k < 7; ++k)
    truth.push_back(Truth(k, k < 2 || k > 3, k == 2 || k == 3));
  std::vector<ReplayedFrame> replayed;
  for (long k = 0; k < 7; ++k) {
    replayed.push_back(Replayed(k, "tracking", 4.0, 0.01, 0.1));
    replayed.back().source = k >= 2 && k <= 5 ? "odometry" : "tracker";
  }
  const DriveMetrics m = ComputeDriveMetrics(truth, replayed, 50.0);
  EXPECT_EQ(m.observable, 5);
  EXPECT_EQ(m.observable_tracking, 5);
  EXPECT_EQ(m.observable_tracking_coasted, 2);  // frames 4, 5
  ASSERT_EQ(m.recoveries.size(), 1u);
  EXPECT_EQ(m.recoveries[0].first_observable, 4);
  EXPECT_EQ(m.recoveries[0].recovered, 6);
  EXPECT_EQ(m.recoveries[0].frames_to_recover, 2);
  const std::string table = FormatDriveTable({{"coast", m, 2.0}});
  EXPECT_NE(table.find("| ... of which coasted on the odometry (no image fix) | 40.0 % |"),
            std::string::npos)
      << table;
}

TEST(DriveMetrics, NeverRecoveredAndNoBlackout) {
  std::vector<FrameTruth> truth = {Truth(0, true), Truth(1, false, true), Truth(2, true)};
  const std::vector<ReplayedFrame> replayed = {Replayed(0, "tracking", 1.0, 0.01),
                                               Replayed(1, "lost", 1.0), Replayed(2, "lost", 1.0)};
  DriveMetrics m = ComputeDriveMetrics(truth, replayed, 0.0);
  ASSERT_EQ(m.recoveries.size(), 1u);
  EXPECT_EQ(m.recoveries[0].frames_to_recover, -1);
  EXPECT_NE(FormatDriveTable({{"a", m, 0.0}}).find("| never |"), std::string::npos);
  truth[1].covered = false;
  m = ComputeDriveMetrics(truth, replayed, 0.0);
  EXPECT_TRUE(m.recoveries.empty());
  EXPECT_NE(FormatDriveTable({{"a", m, 0.0}}).find("| no blackout |"), std::string::npos);
}

// Two kidnaps (put down on frames 3 and 8): after the first, frame 3 is not observable, a
// `tracking` pose 30 cm off on frame 4 is wrong, a degraded pose on 5 does not count, and a
// `tracking` pose within bounds on 6 recovers (2 frames after the first observable, 4); the
// second never recovers.
TEST(DriveMetrics, FramesToRecoverAfterEachKidnap) {
  std::vector<FrameTruth> truth;
  for (long k = 0; k < 10; ++k)
    truth.push_back(Truth(k, k != 3));
  const std::vector<ReplayedFrame> replayed = {
      Replayed(0, "tracking", 1.0, 0.01), Replayed(1, "tracking", 1.0, 0.01),
      Replayed(2, "tracking", 1.0, 0.01), Replayed(3, "lost", 1.0),
      Replayed(4, "tracking", 1.0, 0.30), Replayed(5, "degraded", 1.0, 0.01),
      Replayed(6, "tracking", 1.0, 0.02), Replayed(7, "tracking", 1.0, 0.02),
      Replayed(8, "lost", 1.0),           Replayed(9, "degraded", 1.0, 0.01)};
  DriveMetrics m = ComputeDriveMetrics(truth, replayed, 10.0);
  AddKidnapRecoveries(truth, replayed, {3, 8}, DriveMetricsOptions(), &m);
  ASSERT_EQ(m.kidnaps.size(), 2u);
  EXPECT_EQ(m.kidnaps[0].first_observable, 4);
  EXPECT_EQ(m.kidnaps[0].recovered, 6);
  EXPECT_EQ(m.kidnaps[0].frames_to_recover, 2);
  EXPECT_EQ(m.kidnaps[0].wrong_tracking, 1);
  EXPECT_EQ(m.kidnaps[1].frames_to_recover, -1);
  EXPECT_EQ(m.kidnaps[1].wrong_tracking, 0);
  const std::string table = FormatDriveTable({{"drive", m, 1.0}});
  EXPECT_NE(table.find("| 2, never (1 wrong `tracking` poses meanwhile) |"), std::string::npos)
      << table;
}

TEST(ReplayFrames, ReadByColumnName) {
  const std::string text =
      "frame,time,status,projection_error_deg,moving_edges,time_ms,source,passes,"
      "translation_error_m,rotation_error_deg,note\n"
      "0,0.000000,tracking,3.1,120,4.500,matcher,2,0.01234,0.1000,\n"
      "1,0.100000,lost,,,30.000,,0,,,no consistent hypothesis; too few edges\n";
  const std::vector<ReplayedFrame> f = ParseReplayFrames(text, "frames.csv");
  ASSERT_EQ(f.size(), 2u);
  EXPECT_TRUE(f[0].has_pose);
  EXPECT_NEAR(*f[0].translation_error_m, 0.01234, kTol);
  EXPECT_NEAR(f[0].step_ms, 4.5, kTol);
  EXPECT_EQ(f[0].source, "matcher");
  EXPECT_FALSE(f[1].has_pose);
  EXPECT_EQ(f[1].status, "lost");
  EXPECT_EQ(f[1].note, "no consistent hypothesis; too few edges");
  EXPECT_THROW(ParseReplayFrames("frame,time,status\n0,0,lost\n", "f.csv"), InputError);
  EXPECT_THROW(ParseReplayFrames(text + "2,x,lost,,,1,,0,,,\n", "f.csv"), InputError);
}

}  // namespace
}  // namespace linetrack::app
