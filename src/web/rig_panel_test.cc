#include "web/rig_panel.h"

#include <gtest/gtest.h>

#include <cmath>

#include "control/rig_test_util.h"

namespace softsight {
namespace {

constexpr double kFps = 30.0;
using State = RigPanel::State;
using Action = ControllerOutput::Action;

// The simulated rig in-process (rig_test_util.h): the frames' clock is the rig's, advanced one
// camera period per frame, and the link's deadlines are on it too. Nothing waits for real.
class PanelHarness {
 public:
  explicit PanelHarness(const ActuatorModel& model = {})
      : rig_(RigOptions{}), transport_(rig_), link_(transport_, LinkOptions{}, transport_.environment()),
        session_(ControllerOptions{}, link_, ControlTarget{}) {
    info_ = session_.start();
    panel_ = std::make_unique<RigPanel>(session_, info_, transport_.name(), model);
  }

  // `seconds` of frames; the measurement is the rig's true angle (a perfect camera).
  void run(double seconds) {
    const int frames = static_cast<int>(std::lround(seconds * kFps));
    for (int i = 0; i < frames; ++i) {
      if (frame_ > 0) rig_.advance(1.0 / kFps);
      panel_->step(frame_ / kFps, rig_.snapshot().angle_deg);
      ++frame_;
    }
  }
  double now_s() const { return (frame_ - 1) / kFps; }

  SimulatedRig& rig() { return rig_; }
  RigPanel& panel() { return *panel_; }
  testing::DirectRigTransport& transport() { return transport_; }
  const ControllerOptions& controller() const { return session_.controller().options(); }

 private:
  SimulatedRig rig_;
  testing::DirectRigTransport transport_;
  BoardLink link_;
  ControlSession session_;
  BoardInfo info_;
  std::unique_ptr<RigPanel> panel_;
  int64_t frame_ = 0;
};

TEST(RigPanelTest, IdleVentsEveryFrameAndARunBendsTheActuator) {
  PanelHarness h;
  h.run(0.5);
  EXPECT_EQ(h.panel().state(), State::kIdle);
  EXPECT_TRUE(h.panel().last_sample().board.vented());
  EXPECT_EQ(h.panel().run_target(120.0, /*page=*/1), "");
  h.run(4.0);
  EXPECT_EQ(h.panel().state(), State::kRunning);
  EXPECT_NEAR(h.rig().snapshot().angle_deg, 120.0, 2.0);
  EXPECT_EQ(*h.panel().last_sample().target_deg, 120.0);
  // A new target keeps the run going.
  EXPECT_EQ(h.panel().run_target(150.0, 1), "");
  h.run(3.0);
  EXPECT_NEAR(h.rig().snapshot().angle_deg, 150.0, 2.0);
  EXPECT_NE(h.panel().status_json().find("\"state\":\"running\""), std::string::npos);
}

TEST(RigPanelTest, StopVentsAtOnceFromAnyStateAndThePressureFalls) {
  PanelHarness h;
  ASSERT_EQ(h.panel().run_target(110.0, 1), "");
  h.run(3.0);
  const double before_kpa = h.rig().snapshot().pressure_kpa;
  ASSERT_GT(before_kpa, 5.0);
  const int64_t updates = h.panel().updates();
  // Between two frames: the STOP goes to the board now, its answer says vented.
  h.panel().stop("test");
  EXPECT_EQ(h.panel().state(), State::kIdle);
  EXPECT_GT(h.panel().updates(), updates);
  EXPECT_EQ(h.panel().last_sample().action, Action::kVent);
  EXPECT_TRUE(h.panel().last_sample().board.vented());
  h.run(1.0);
  EXPECT_LT(h.rig().snapshot().pressure_kpa, 0.3 * before_kpa);
  EXPECT_NEAR(h.rig().snapshot().angle_deg, 180.0, 5.0);
  // STOP again, idle: still vents, never throws.
  h.panel().stop("again");
  EXPECT_TRUE(h.panel().last_sample().board.vented());
  const std::vector<std::string> said = h.panel().take_messages();
  ASSERT_FALSE(said.empty());
  EXPECT_NE(said.back().find("STOP"), std::string::npos);
}

TEST(RigPanelTest, TheOwnerLeavingMidRunHoldsTheSetpointForHoldSThenVents) {
  PanelHarness h;
  ASSERT_EQ(h.panel().run_target(120.0, /*page=*/7), "");
  h.run(2.0);
  const double held_kpa = *h.panel().last_sample().setpoint_kpa;
  ASSERT_GT(held_kpa, 3.0);
  // Another page leaving changes nothing.
  h.panel().page_left(8);
  EXPECT_EQ(h.panel().state(), State::kRunning);
  const double left_at_s = h.now_s();
  h.panel().page_left(7);
  EXPECT_EQ(h.panel().state(), State::kHolding);
  const double hold_s = h.controller().hold_s;
  // Frame by frame on the frames' clock: the setpoint held exactly, until hold_s has passed.
  double vented_at_s = -1.0;
  for (int i = 0; i < 60 && vented_at_s < 0.0; ++i) {
    h.run(1.0 / kFps);
    const ControlSample& s = h.panel().last_sample();
    if (h.panel().state() == State::kHolding) {
      EXPECT_EQ(s.action, Action::kHold);
      EXPECT_DOUBLE_EQ(*s.setpoint_kpa, held_kpa);
      EXPECT_LT(h.now_s() - left_at_s, hold_s - 1e-9);
    } else {
      EXPECT_EQ(h.panel().state(), State::kIdle);
      EXPECT_EQ(s.action, Action::kVent);
      EXPECT_TRUE(s.board.vented());
      vented_at_s = h.now_s();
    }
  }
  ASSERT_GE(vented_at_s, 0.0) << "never vented";
  EXPECT_GE(vented_at_s - left_at_s, hold_s - 1e-9);
  EXPECT_LE(vented_at_s - left_at_s, hold_s + 1.0 / kFps + 1e-9);
  h.run(1.0);
  EXPECT_EQ(h.panel().state(), State::kIdle);
  EXPECT_TRUE(h.panel().last_sample().board.vented());
}

TEST(RigPanelTest, StopDuringTheHoldVentsAtOnce) {
  PanelHarness h;
  ASSERT_EQ(h.panel().run_target(120.0, 3), "");
  h.run(2.0);
  h.panel().page_left(3);
  h.run(0.1);
  ASSERT_EQ(h.panel().state(), State::kHolding);
  h.panel().stop("test");
  EXPECT_EQ(h.panel().state(), State::kIdle);
  EXPECT_TRUE(h.panel().last_sample().board.vented());
}

TEST(RigPanelTest, APageLeavingWhileIdleChangesNothing) {
  PanelHarness h;
  h.run(0.2);
  h.panel().page_left(1);
  EXPECT_EQ(h.panel().state(), State::kIdle);
}

TEST(RigPanelTest, AProfileRunsFromItsStartAndKeepsItsLastTarget) {
  PanelHarness h;
  h.run(0.2);
  ASSERT_EQ(h.panel().run_profile(TargetProfile::Parse("step 140\nhold 1\nstep 130\nhold 1\n", "t"), 2), "");
  h.run(0.5);
  EXPECT_EQ(*h.panel().last_sample().target_deg, 140.0);
  h.run(2.5);
  EXPECT_EQ(*h.panel().last_sample().target_deg, 130.0);
  EXPECT_EQ(h.panel().state(), State::kRunning);
}

TEST(RigPanelTest, ATargetBeyondTheIdentifiedReachIsRefusedAndChangesNothing) {
  ActuatorModel model;
  model.straight_deg = 180.0;
  model.bend_start_kpa = 3.0;
  model.slope_deg_per_kpa = 1.0;  // 45 kPa bends it 42 deg at most: 138 deg.
  model.valid_min_kpa = 0.0;
  model.valid_max_kpa = 45.0;
  model.valid_min_deg = 138.0;
  model.valid_max_deg = 180.0;
  PanelHarness h(model);
  h.run(0.2);
  const std::string why = h.panel().run_target(60.0, 1);
  EXPECT_NE(why.find("reach"), std::string::npos) << why;
  EXPECT_EQ(h.panel().state(), State::kIdle);
  h.run(0.2);
  EXPECT_TRUE(h.panel().last_sample().board.vented());
}

TEST(RigPanelTest, AFailedLinkEndsInFailedWithoutThrowingAndStopStillReturns) {
  PanelHarness h;
  ASSERT_EQ(h.panel().run_target(120.0, 1), "");
  h.run(1.0);
  h.transport().disconnect();
  EXPECT_NO_THROW(h.run(0.2));
  EXPECT_EQ(h.panel().state(), State::kFailed);
  EXPECT_NE(h.panel().run_target(150.0, 1), "");
  EXPECT_NO_THROW(h.panel().stop("test"));
  const std::vector<std::string> said = h.panel().take_messages();
  ASSERT_FALSE(said.empty());
  EXPECT_NE(said.back().find("watchdog"), std::string::npos) << said.back();
}

TEST(RigPanelTest, TheSameFrameTimeTwiceIsOneStep) {
  PanelHarness h;
  h.panel().step(1.0, 180.0);
  const int64_t updates = h.panel().updates();
  h.panel().step(1.0, 180.0);
  h.panel().step(0.5, 180.0);
  EXPECT_EQ(h.panel().updates(), updates);
}

TEST(RigPanelTest, TheLimitsNameTheBoardAndTheHost) {
  PanelHarness h;
  const std::string limits = h.panel().limits_json();
  for (const char* key : {"\"board_limit_kpa\":", "\"max_kpa\":", "\"watchdog_ms\":", "\"hold_s\":",
                          "\"port\":"}) {
    EXPECT_NE(limits.find(key), std::string::npos) << key << " in " << limits;
  }
}

}  // namespace
}  // namespace softsight
