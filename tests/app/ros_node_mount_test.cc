// `linetrack ros --mount mount.json` against a real roscore: with the head's angles from
// joint_states, the camera on the head at its calibrated mount (off the nominal geometry) gives the
// base poses of the truth; a mount the node cannot use is refused with one line and exit 2.
#include <sys/wait.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/app/calibrated_head.h"
#include "tests/app/ros_node_fixture.h"
#include "tracking/head/head_pointing.h"

namespace linetrack::app {
namespace {

using namespace ros_node_test;  // NOLINT: the fixture of these tests
using test::CalibratedHead;
using test::kCrossingHeightM;

std::string WriteMountJson(const HeadGeometry& head, const fs::path& dir) {
  return test::WriteMountJson(head, kCameraFile, dir);
}

// The head's angles from joint_states and the camera's calibrated mount on the head from --mount
// (its floor height in place of --height): the frames rendered with the camera on that head, the
// base poses must come back as in the joints test. The nominal geometry would put the camera 76.5
// mm and 1.2 degrees off the truth.
TEST(RosNodeMount, TakesTheCalibratedMountWithTheJointStates) {
  const HeadGeometry head = CalibratedHead();
  const test::RenderedDrive hall =
      test::RenderHallDrive(kFrames, DegToRad(kTfPanAmplitudeDeg), [&](const SequenceFrame& f) {
        return CamFromWorldOnHead(head, f.base.Planar(), kCrossingHeightM, f.pan, f.camera.tilt);
      });
  const fs::path dir =
      fs::temp_directory_path() / ("linetrack_ros_mount_" + std::to_string(getpid()));
  const std::string mount = WriteMountJson(head, dir);
  NodeUnderTest node({"--odom-wait", "1", "--mount", mount, "--pan-joint", "head_pan",
                      "--tilt-joint", "head_tilt", "joint_states:=/robot/joints", "--camera",
                      kCameraFile});
  ASSERT_TRUE(node.started()) << "roscore or the node did not start";
  DriveWithJointStates(node, hall);
  EXPECT_EQ(node.Stop(), 0) << "the node's exit status";
  fs::remove_all(dir);
}

// What `linetrack ros` with `flags` did against the running master, once it exited.
struct Refusal {
  int exit_code = -1;   // -1: killed, or still running at the deadline
  std::string stderr_;  // its whole stderr
};

// Runs `linetrack ros --model hall.cao --camera camera_wide.xml FLAGS` through the shell, its
// stderr to `dir`/stderr.txt.
Refusal RunRefused(const std::vector<std::string>& flags, const fs::path& dir) {
  const fs::path err = dir / "stderr.txt";
  std::string command = std::string("exec '") + LINETRACK_EXE + "' ros --model '" + kSource +
                        "/models/hall.cao' --camera '" + kCameraFile + "'";
  for (const std::string& flag : flags)
    command += " '" + flag + "'";
  command += " 2> '" + err.string() + "'";
  ChildProcess node({"sh", "-c", command});
  Refusal r;
  if (!WaitFor([&] { return !node.Running(); }, kDeadlineS)) return r;
  const int status = node.Stop();
  if (WIFEXITED(status)) r.exit_code = WEXITSTATUS(status);
  std::ifstream in(err);
  r.stderr_.assign(std::istreambuf_iterator<char>(in), {});
  return r;
}

// One line on stderr, containing `what`, and exit 2.
void ExpectRefused(const Refusal& r, const std::string& what) {
  EXPECT_EQ(r.exit_code, 2) << r.stderr_;
  EXPECT_EQ(std::count(r.stderr_.begin(), r.stderr_.end(), '\n'), 1) << r.stderr_;
  EXPECT_NE(r.stderr_.find(what), std::string::npos) << r.stderr_;
}

// --mount with the head from TF or fixed, a mount file that is not one or is missing, and a mount
// without a floor height nor --height: one line on stderr naming the flag or the file, exit 2.
TEST(RosNodeMount, RefusesAMountItCannotUse) {
  const fs::path dir =
      fs::temp_directory_path() / ("linetrack_ros_bad_" + std::to_string(getpid()));
  RosCore core(dir / "ros");
  ASSERT_TRUE(core.ready()) << "roscore did not start";
  const std::string good = WriteMountJson(CalibratedHead(), dir);
  const std::string bad = (dir / "bad.json").string();
  std::ofstream(bad) << "{\"tilt_from_camera\": [1, 0, 0]}\n";
  std::ifstream in(good);
  nlohmann::json j = nlohmann::json::parse(in);
  j.erase("floor");
  const std::string no_floor = (dir / "no_floor.json").string();
  std::ofstream(no_floor) << j.dump();
  const std::string missing = (dir / "missing.json").string();
  const std::vector<std::string> joints = {"--pan-joint", "head_pan", "--tilt-joint", "head_tilt"};
  auto with_joints = [&](std::vector<std::string> flags) {
    flags.insert(flags.end(), joints.begin(), joints.end());
    return flags;
  };
  ExpectRefused(RunRefused({"--mount", good, "--head", "tf"}, dir), "--mount");
  ExpectRefused(
      RunRefused({"--mount", good, "--head", "fixed", "--height", "1.3", "--tilt", "5"}, dir),
      "--mount");
  ExpectRefused(RunRefused(with_joints({"--mount", bad}), dir), bad);
  ExpectRefused(RunRefused(with_joints({"--mount", missing}), dir), missing);
  ExpectRefused(RunRefused(with_joints({"--mount", no_floor}), dir), "--height");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace linetrack::app
