// The PTU-D46 protocol parser, and the driver against the emulated unit on a pseudo-terminal:
// start-up, queries, position and velocity commands, limits, error replies, asynchronous limit
// events and timeouts. The emulator's clock moves only when the test says so.
#include <gtest/gtest.h>

#include <cmath>

#include "models/errors.h"
#include "models/geometry.h"
#include "tests/support/ptu_emulator.h"
#include "tracking/head/head_factory.h"
#include "tracking/head/ptu_driver.h"
#include "tracking/head/ptu_protocol.h"
#include "tracking/sim/simulated_head.h"

namespace linetrack {
namespace {

constexpr double kArcsec = 185.1428;                          // the emulator's resolution
constexpr double kCountRad = kArcsec / 3600.0 * kPi / 180.0;  // one count in radians
constexpr double kAngleTolRad = 1e-12;
constexpr double kOneCountTolRad = 1.0 * kCountRad;  // positions are whole counts
constexpr double kReplyTimeoutS = 0.2;

TEST(PtuProtocol, ParsesRepliesEchoAndEvents) {
  PtuLine p = ParsePtuLine("* 1000");
  EXPECT_EQ(p.kind, PtuLine::Kind::kSuccess);
  EXPECT_EQ(p.text, "1000");
  p = ParsePtuLine("PP * Current Pan position is -500");  // echo on, verbose
  EXPECT_EQ(p.kind, PtuLine::Kind::kSuccess);
  EXPECT_EQ(p.text, "Current Pan position is -500");
  p = ParsePtuLine("PP3200 ! Maximum allowable Pan position is 3090");
  EXPECT_EQ(p.kind, PtuLine::Kind::kError);
  EXPECT_EQ(p.text, "Maximum allowable Pan position is 3090");
  p = ParsePtuLine("!P* 100");
  EXPECT_EQ(p.pan_limit_events, 1);
  EXPECT_EQ(p.kind, PtuLine::Kind::kSuccess);
  EXPECT_EQ(p.text, "100");
  p = ParsePtuLine("!T!P!T! Illegal Command");
  EXPECT_EQ(p.pan_limit_events, 1);
  EXPECT_EQ(p.tilt_limit_events, 2);
  EXPECT_EQ(p.kind, PtuLine::Kind::kError);
  EXPECT_EQ(p.text, "Illegal Command");
  p = ParsePtuLine("!P");
  EXPECT_EQ(p.kind, PtuLine::Kind::kNone);
  EXPECT_EQ(p.pan_limit_events, 1);
  EXPECT_EQ(ParsePtuLine("Pan-Tilt Controller v2.12").kind, PtuLine::Kind::kNone);
  EXPECT_EQ(ParsePtuLine("*").text, "");

  int pan = 0, tilt = 0;
  EXPECT_TRUE(TakePtuEvents("!P!T!P", &pan, &tilt));
  EXPECT_EQ(pan, 2);
  EXPECT_EQ(tilt, 1);
  EXPECT_FALSE(TakePtuEvents("!", &pan, &tilt));
  EXPECT_FALSE(TakePtuEvents("!P* 3", &pan, &tilt));
}

TEST(PtuProtocol, ReadsTerseAndVerboseNumbers) {
  double v = 0.0;
  ASSERT_TRUE(ParsePtuNumber("1000", &v));
  EXPECT_EQ(v, 1000.0);
  ASSERT_TRUE(ParsePtuNumber("-500", &v));
  EXPECT_EQ(v, -500.0);
  ASSERT_TRUE(ParsePtuNumber("Current Pan position is -500", &v));
  EXPECT_EQ(v, -500.0);
  ASSERT_TRUE(ParsePtuNumber("185.1428 seconds arc per Pan position", &v));
  EXPECT_EQ(v, 185.1428);
  ASSERT_TRUE(ParsePtuNumber("Maximum Pan speed is 2902 positions/sec", &v));
  EXPECT_EQ(v, 2902.0);
  ASSERT_TRUE(ParsePtuNumber("Pan acceleration is 2000 positions/sec^2", &v));
  EXPECT_EQ(v, 2000.0);
  EXPECT_FALSE(ParsePtuNumber("ASCII terse mode", &v));
}

TEST(PtuProtocol, CountsToRadiansWithSigns) {
  // 185.1428 arc-seconds per count: 21.3 degrees is about 414 counts (the manual's example).
  EXPECT_NEAR(PtuRadiansToCounts(DegToRad(21.3), kArcsec, 1), 414.16, 0.01);
  EXPECT_NEAR(PtuCountsToRadians(1.0, kArcsec, 1), kCountRad, kAngleTolRad);
  EXPECT_NEAR(PtuCountsToRadians(-604.0, kArcsec, -1), 604.0 * kCountRad, kAngleTolRad);
  EXPECT_NEAR(PtuRadiansToCounts(PtuCountsToRadians(1234.0, kArcsec, -1), kArcsec, -1), 1234.0,
              1e-9);
}

class PtuDriverTest : public ::testing::Test {
 protected:
  void StartEmulator(const PtuEmulatorOptions& options = {}) {
    std::string why;
    emulator_ = PtuEmulator::Start(options, &why);
    ASSERT_TRUE(emulator_) << why;
  }
  PtuOptions DriverOptions() const {
    PtuOptions options;
    options.device = emulator_->device_path();
    options.reply_timeout_s = kReplyTimeoutS;
    return options;
  }
  void OpenDriver() {
    HeadResult result;
    driver_ = PtuDriver::Open(DriverOptions(), &result);
    ASSERT_TRUE(driver_) << result.message;
  }
  void SetUp() override {
    StartEmulator();
    OpenDriver();
  }
  HeadState ReadState() {
    HeadState state;
    const HeadResult r = driver_->Read(&state);
    EXPECT_TRUE(r.ok()) << r.message;
    return state;
  }

  std::unique_ptr<PtuEmulator> emulator_;
  std::unique_ptr<PtuDriver> driver_;
};

TEST_F(PtuDriverTest, OpensTheUnitAndReadsItsLimits) {
  const std::vector<std::string> commands = emulator_->commands();
  ASSERT_GE(commands.size(), 4u);
  EXPECT_EQ(commands[0], "ED");  // the unit powers up echoing and verbose
  EXPECT_EQ(commands[1], "FT");
  EXPECT_EQ(driver_->unit().pan_resolution_arcsec, kArcsec);
  EXPECT_EQ(driver_->unit().pan_min, -3090);
  EXPECT_EQ(driver_->unit().tilt_max, 604);
  EXPECT_EQ(driver_->unit().pan_max_speed, 2902);
  const HeadLimits limits = driver_->Limits();
  EXPECT_NEAR(limits.pan_min, -3090 * kCountRad, kAngleTolRad);
  EXPECT_NEAR(limits.pan_max, 3090 * kCountRad, kAngleTolRad);
  // Positive tilt counts look up on a D46; the project's tilt is positive looking down.
  EXPECT_NEAR(limits.tilt_min, -604 * kCountRad, kAngleTolRad);
  EXPECT_NEAR(limits.tilt_max, 907 * kCountRad, kAngleTolRad);
  EXPECT_NEAR(limits.max_pan_speed, 2902 * kCountRad, kAngleTolRad);
  EXPECT_NE(driver_->Describe().find(emulator_->device_path()), std::string::npos);
}

TEST_F(PtuDriverTest, ReadsPositionsInRadians) {
  emulator_->SetPositions(1000, -300);
  const HeadState state = ReadState();
  EXPECT_NEAR(state.pan, 1000 * kCountRad, kAngleTolRad);
  EXPECT_NEAR(state.tilt, 300 * kCountRad, kAngleTolRad);  // 300 counts down
  EXPECT_EQ(state.mode, HeadMode::kPosition);
}

TEST_F(PtuDriverTest, MovesToAPositionAtTheMoveSpeed) {
  const double pan = DegToRad(10.0), tilt = DegToRad(10.0);  // 194 counts each
  ASSERT_TRUE(driver_->MoveTo(pan, tilt).ok());
  EXPECT_TRUE(ReadState().moving);
  // Move speed: half of 2902 counts/s = 1451 counts/s, so 0.1 s moves 145.1 counts.
  emulator_->Advance(0.1);
  EXPECT_NEAR(emulator_->pan_position(), 145.1, 1e-9);
  EXPECT_NEAR(emulator_->tilt_position(), -145.1, 1e-9);  // tilting down: negative counts
  emulator_->Advance(1.0);
  const HeadState state = ReadState();
  EXPECT_NEAR(state.pan, pan, kOneCountTolRad);
  EXPECT_NEAR(state.tilt, tilt, kOneCountTolRad);
  EXPECT_FALSE(state.moving);
}

TEST_F(PtuDriverTest, RefusesTargetsOutsideTheLimits) {
  const std::size_t sent = emulator_->commands().size();
  const HeadResult r = driver_->MoveTo(DegToRad(170.0), 0.0);
  EXPECT_EQ(r.status, HeadStatus::kRejected);
  EXPECT_NE(r.message.find("outside"), std::string::npos) << r.message;
  EXPECT_EQ(emulator_->commands().size(), sent);  // nothing reached the unit
}

TEST_F(PtuDriverTest, VelocityModeIntegratesOnTheEmulatorClock) {
  ASSERT_TRUE(driver_->SetVelocity(0.2, -0.1).ok());
  EXPECT_TRUE(emulator_->velocity_mode());
  emulator_->Advance(1.0);
  const HeadState state = ReadState();
  EXPECT_EQ(state.mode, HeadMode::kVelocity);
  EXPECT_TRUE(state.moving);
  // Speeds are whole counts per second: within one count of the exact rate after 1 s.
  EXPECT_NEAR(state.pan, 0.2, kOneCountTolRad);
  EXPECT_NEAR(state.tilt, -0.1, kOneCountTolRad);
  EXPECT_NEAR(state.pan_rate, 0.2, kCountRad);
  ASSERT_TRUE(driver_->Stop().ok());
  const double stopped_at = emulator_->pan_position();
  emulator_->Advance(1.0);
  EXPECT_EQ(emulator_->pan_position(), stopped_at);
  EXPECT_FALSE(ReadState().moving);
}

TEST_F(PtuDriverTest, LimitEventsStopTheAxisAndAreReported) {
  emulator_->SetPositions(3000, 0);
  ASSERT_TRUE(driver_->SetVelocity(10.0, 0.0).ok());  // clamped to the maximum speed
  EXPECT_EQ(emulator_->pan_speed(), 2902.0);
  emulator_->Advance(1.0);  // reaches 3090 and sends "!P"
  HeadState state = ReadState();
  EXPECT_TRUE(state.pan_at_limit);
  EXPECT_FALSE(state.tilt_at_limit);
  EXPECT_NEAR(state.pan, 3090 * kCountRad, kAngleTolRad);
  EXPECT_EQ(state.pan_rate, 0.0);
  EXPECT_EQ(driver_->pan_limit_events(), 1);
  // Back away from the limit.
  ASSERT_TRUE(driver_->SetVelocity(-0.1, 0.0).ok());
  emulator_->Advance(0.5);
  state = ReadState();
  EXPECT_FALSE(state.pan_at_limit);
  EXPECT_LT(state.pan, 3090 * kCountRad);
  // An event arriving on its own, between exchanges, is counted too.
  emulator_->Inject("!T");
  ReadState();
  EXPECT_EQ(driver_->tilt_limit_events(), 1);
}

TEST_F(PtuDriverTest, IgnoresNoiseOnTheLine) {
  emulator_->SetPositions(42, 0);
  emulator_->Inject("Pan-Tilt Controller v2.12.1d1\r\n\r\n");
  const HeadState state = ReadState();
  EXPECT_NEAR(state.pan, 42 * kCountRad, kAngleTolRad);
}

TEST_F(PtuDriverTest, SilentUnitTimesOutAndRecovers) {
  emulator_->SetResponsive(false);
  HeadState state;
  HeadResult r = driver_->Read(&state);
  EXPECT_EQ(r.status, HeadStatus::kTimeout);
  EXPECT_NE(r.message.find("no reply to 'PP'"), std::string::npos) << r.message;
  r = driver_->SetVelocity(0.1, 0.0);
  EXPECT_EQ(r.status, HeadStatus::kTimeout);
  emulator_->SetResponsive(true);
  emulator_->SetPositions(7, 0);
  r = driver_->Read(&state);
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_NEAR(state.pan, 7 * kCountRad, kAngleTolRad);
}

// Error replies in the middle of a run are results naming the unit's message, nothing is
// assumed done, and the line stays in step: the next exchange reads its own reply.
TEST_F(PtuDriverTest, ErrorRepliesDuringARunAreResultsAndKeepTheLineInStep) {
  emulator_->SetPositions(250, -100);
  emulator_->RejectNextCommand("Illegal Command");
  HeadState state;
  HeadResult r = driver_->Read(&state);
  EXPECT_EQ(r.status, HeadStatus::kRejected);
  EXPECT_NE(r.message.find("Illegal Command"), std::string::npos) << r.message;
  state = ReadState();
  EXPECT_NEAR(state.pan, 250 * kCountRad, kAngleTolRad);
  EXPECT_NEAR(state.tilt, 100 * kCountRad, kAngleTolRad);

  // A refused switch to velocity mode: the driver stays in position mode and tries again.
  emulator_->RejectNextCommand("Illegal Command");
  r = driver_->SetVelocity(0.1, 0.0);
  EXPECT_EQ(r.status, HeadStatus::kRejected);
  EXPECT_EQ(ReadState().mode, HeadMode::kPosition);
  ASSERT_TRUE(driver_->SetVelocity(0.1, 0.0).ok());
  EXPECT_TRUE(emulator_->velocity_mode());
  EXPECT_EQ(ReadState().mode, HeadMode::kVelocity);

  // A refused velocity: the rate the driver reports is not the refused one.
  emulator_->RejectNextCommand("Pan speed cannot exceed 2902 positions/sec");
  r = driver_->SetVelocity(0.3, 0.0);
  EXPECT_EQ(r.status, HeadStatus::kRejected);
  EXPECT_NE(r.message.find("cannot exceed"), std::string::npos) << r.message;
  EXPECT_NEAR(ReadState().pan_rate, 0.1, kCountRad);

  // A refused position command.
  emulator_->RejectNextCommand("Illegal Command Argument");
  r = driver_->MoveTo(0.0, 0.0);
  EXPECT_EQ(r.status, HeadStatus::kRejected);
  ASSERT_TRUE(driver_->MoveTo(0.0, 0.0).ok());
  emulator_->Advance(2.0);
  EXPECT_NEAR(ReadState().pan, 0.0, kOneCountTolRad);
  ASSERT_TRUE(driver_->Stop().ok());
}

// The exact joint limits are reachable (no count lost to rounding), and a limit error from the
// unit itself (its limits differing from those it reported) comes back as a rejection.
TEST_F(PtuDriverTest, ReachesTheExactLimitsAndReportsTheUnitsLimitErrors) {
  const HeadLimits limits = driver_->Limits();
  ASSERT_TRUE(driver_->MoveTo(limits.pan_max, limits.tilt_min).ok());
  emulator_->Advance(5.0);
  EXPECT_EQ(emulator_->pan_position(), 3090.0);
  EXPECT_EQ(emulator_->tilt_position(), 604.0);  // looking up: positive counts on a D46
  HeadState state = ReadState();
  EXPECT_NEAR(state.pan, limits.pan_max, kAngleTolRad);
  EXPECT_NEAR(state.tilt, limits.tilt_min, kAngleTolRad);
  ASSERT_TRUE(driver_->MoveTo(limits.pan_min, limits.tilt_max).ok());
  emulator_->Advance(10.0);
  EXPECT_EQ(emulator_->pan_position(), -3090.0);
  EXPECT_EQ(emulator_->tilt_position(), -907.0);
  // The unit's limit error, as it words it, comes back as a rejection.
  emulator_->RejectNextCommand("Maximum allowable Pan position is 3090");
  const HeadResult r = driver_->MoveTo(limits.pan_max, 0.0);
  EXPECT_EQ(r.status, HeadStatus::kRejected);
  EXPECT_NE(r.message.find("Maximum allowable Pan position"), std::string::npos) << r.message;
}

// Pure velocity mode into the tilt limit: "!T" stops the axis and flags it; the pan keeps going.
TEST_F(PtuDriverTest, TiltLimitEventInVelocityMode) {
  emulator_->SetPositions(0, 550);                     // 54 counts below the upper tilt limit
  ASSERT_TRUE(driver_->SetVelocity(0.05, -0.2).ok());  // tilting up: towards TX = 604
  emulator_->Advance(0.5);
  const HeadState state = ReadState();
  EXPECT_TRUE(state.tilt_at_limit);
  EXPECT_FALSE(state.pan_at_limit);
  EXPECT_EQ(state.tilt_rate, 0.0);
  EXPECT_NEAR(state.pan_rate, 0.05, kCountRad);
  EXPECT_EQ(emulator_->tilt_position(), 604.0);
  EXPECT_GT(emulator_->pan_position(), 0.0);
  EXPECT_EQ(driver_->tilt_limit_events(), 1);
  ASSERT_TRUE(driver_->Stop().ok());
}

// The same, without opening the driver in SetUp.
class PtuDriverOpen : public PtuDriverTest {
 protected:
  void SetUp() override {}
};

TEST_F(PtuDriverOpen, ErrorRepliesDuringStartUpAreResults) {
  PtuEmulatorOptions emulator_options;
  emulator_options.min_speed = 2000;  // above the driver's move speed (1451 counts/s)
  StartEmulator(emulator_options);
  HeadResult result;
  EXPECT_FALSE(PtuDriver::Open(DriverOptions(), &result));
  EXPECT_EQ(result.status, HeadStatus::kRejected);
  EXPECT_NE(result.message.find("cannot be less than 2000"), std::string::npos) << result.message;
}

TEST_F(PtuDriverOpen, SilentOrMissingUnits) {
  StartEmulator();
  emulator_->SetResponsive(false);
  PtuOptions options = DriverOptions();
  HeadResult result;
  EXPECT_FALSE(PtuDriver::Open(options, &result));
  EXPECT_EQ(result.status, HeadStatus::kTimeout);
  EXPECT_NE(result.message.find("powered"), std::string::npos) << result.message;

  options.device = "/dev/ttyLINETRACK-none";
  EXPECT_FALSE(PtuDriver::Open(options, &result));
  EXPECT_EQ(result.status, HeadStatus::kIoError);
  EXPECT_NE(result.message.find("/dev/ttyLINETRACK-none"), std::string::npos) << result.message;

  options.pan_sign = 0;
  EXPECT_THROW(PtuDriver::Open(options, &result), InputError);
}

TEST(PtuEmulator, AnswersInVerboseModeWithEcho) {
  std::string why;
  auto emulator = PtuEmulator::Start({}, &why);
  ASSERT_TRUE(emulator) << why;
  SerialLine line;
  ASSERT_TRUE(line.Open(emulator->device_path(), 9600, &why)) << why;
  const auto deadline = SerialLine::Clock::now() + std::chrono::seconds(2);
  ASSERT_TRUE(line.Write("PR PP3200 XX ", deadline, &why)) << why;
  std::string reply;
  ASSERT_EQ(line.ReadLine(deadline, &reply, &why), SerialLine::ReadStatus::kLine) << why;
  EXPECT_EQ(reply, "PR * 185.1428 seconds arc per Pan position");
  ASSERT_EQ(line.ReadLine(deadline, &reply, &why), SerialLine::ReadStatus::kLine) << why;
  EXPECT_EQ(reply, "PP3200 ! Maximum allowable Pan position is 3090");
  ASSERT_EQ(line.ReadLine(deadline, &reply, &why), SerialLine::ReadStatus::kLine) << why;
  EXPECT_EQ(reply, "XX ! Illegal Command");
}

TEST(HeadFactory, OpensPtuAndSimulatedHeads) {
  EXPECT_EQ(ParseHeadSpec("sim").kind, HeadKind::kSim);
  EXPECT_EQ(ParseHeadSpec("ptu:/dev/ttyUSB0").device, "/dev/ttyUSB0");
  EXPECT_THROW(ParseHeadSpec("ptu:"), InputError);
  EXPECT_THROW(ParseHeadSpec("biclops"), InputError);

  HeadOptions options;
  options.ptu.reply_timeout_s = kReplyTimeoutS;
  EXPECT_THROW(OpenHead("sim", options), InputError);  // no simulator given
  options.make_sim = [] { return std::make_unique<SimulatedHead>(); };
  const auto sim = OpenHead("sim", options);
  EXPECT_NE(dynamic_cast<SimulatedHead*>(sim.get()), nullptr);

  std::string why;
  auto emulator = PtuEmulator::Start({}, &why);
  ASSERT_TRUE(emulator) << why;
  const auto ptu = OpenHead("ptu:" + emulator->device_path(), options);
  EXPECT_NE(dynamic_cast<PtuDriver*>(ptu.get()), nullptr);
  EXPECT_THROW(OpenHead("ptu:/dev/ttyLINETRACK-none", options), InputError);
  emulator->SetResponsive(false);
  try {
    OpenHead("ptu:" + emulator->device_path(), options);
    ADD_FAILURE() << "a silent unit must not open";
  } catch (const InputError& e) {
    ADD_FAILURE() << "a silent unit is a failed job, not bad input: " << e.what();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no reply"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace linetrack
