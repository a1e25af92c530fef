// The checks of `control --target-from` (app/target_feed.h) on what arrives, without a socket:
// range and reach as a profile's, the rate limit, malformed messages, and silence.
#include "app/target_feed.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "softsight/core/error.h"

namespace softsight {
namespace {

using ::testing::HasSubstr;

ReceivedTargets Arrived(std::optional<double> deg, int64_t messages = 1) {
  ReceivedTargets arrived;
  arrived.newest_deg = deg;
  arrived.messages = deg ? messages : 0;
  return arrived;
}

// The stiff plant of issue 23: reaches 130.25..180 deg up to 45 kPa.
TargetFeedOptions StiffPlantFeed() {
  TargetFeedOptions options;
  options.model.straight_deg = 180.0;
  options.model.bend_start_kpa = 3.0;
  options.model.slope_deg_per_kpa = 1.2;
  options.model.static_rms_deg = 0.06;
  options.model.valid_max_kpa = 44.95;
  options.model.valid_min_deg = 130.25;
  options.model.valid_max_deg = 180.0;
  options.max_kpa = 45.0;
  return options;
}

TEST(TargetFeed, TargetsOutOfRangeOrReachAreRefusedAndThePreviousOneKept) {
  TargetFeed feed("ipc://t", StiffPlantFeed());
  EXPECT_DOUBLE_EQ(feed.first(Arrived(150.0), 10.0), 150.0);
  EXPECT_EQ(feed.at(0.0, Arrived(140.0)), 140.0);
  EXPECT_EQ(feed.at(0.1, Arrived(200.0)), 140.0);            // Not in [0, 180].
  EXPECT_EQ(feed.at(0.2, Arrived(120.0)), 140.0);            // Beyond the reach.
  EXPECT_EQ(feed.at(0.3, Arrived(std::nan(""))), 140.0);    // Not a number.
  EXPECT_EQ(feed.at(0.4, Arrived(131.0)), 131.0);
  const std::vector<std::string> notes = feed.notes();
  ASSERT_FALSE(notes.empty());
  EXPECT_THAT(notes[0], HasSubstr("6 target messages, 3 refused"));
  EXPECT_THAT(notes[0], HasSubstr("200 deg is not in [0, 180]"));
}

TEST(TargetFeed, AllowSaturationLimitsATargetToTheReach) {
  TargetFeedOptions options = StiffPlantFeed();
  options.allow_saturation = true;
  TargetFeed feed("ipc://t", options);
  EXPECT_DOUBLE_EQ(feed.first(Arrived(100.0), 10.0), ReachOf(options.model, 45.0).most_bent_deg);
  EXPECT_THAT(feed.notes()[0], HasSubstr("1 limited to the actuator's reach"));
}

TEST(TargetFeed, AFirstTargetMissingOrRefusedIsAnErrorNamingTheEndpoint) {
  TargetFeed none("tcp://lab:5557", TargetFeedOptions{});
  ReceivedTargets malformed;
  malformed.messages = 2;
  malformed.malformed = 2;
  malformed.first_problem = "no number angle_deg in {\"angle\":3}";
  try {
    none.first(malformed, 10.0);
    FAIL() << "no target, no error";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("--target-from tcp://lab:5557: no target within 10 s"));
    EXPECT_THAT(e.what(), HasSubstr("2 malformed messages, the first no number angle_deg"));
  }
  TargetFeed refused("tcp://lab:5557", StiffPlantFeed());
  EXPECT_THROW(refused.first(Arrived(90.0), 10.0), InputError);
}

TEST(TargetFeed, ARateLimitMakesAJumpARamp) {
  TargetFeedOptions options;
  options.max_rate_deg_per_s = 10.0;
  TargetFeed feed("ipc://t", options);
  feed.first(Arrived(170.0), 1.0);
  EXPECT_EQ(feed.at(0.0, Arrived(170.0)), 170.0);
  EXPECT_DOUBLE_EQ(*feed.at(0.5, Arrived(150.0)), 165.0);  // 10 deg/s x 0.5 s.
  EXPECT_DOUBLE_EQ(*feed.at(1.0, Arrived(150.0)), 160.0);
  EXPECT_DOUBLE_EQ(*feed.at(2.0, Arrived(150.0)), 150.0);  // Arrived: held there.
  EXPECT_DOUBLE_EQ(*feed.at(2.1, Arrived(150.0)), 150.0);
}

TEST(TargetFeed, SilenceLongerThanTheLimitVentsUntilTheSourceSpeaksAgain) {
  TargetFeedOptions options;
  options.silence_s = 0.5;
  TargetFeed feed("ipc://t", options);
  feed.first(Arrived(150.0), 1.0);
  EXPECT_EQ(feed.at(0.0, Arrived(std::nullopt)), 150.0);  // Heard just before the first frame.
  EXPECT_EQ(feed.at(0.5, Arrived(std::nullopt)), 150.0);  // Silent exactly the limit: not yet.
  EXPECT_EQ(feed.at(0.6, Arrived(std::nullopt)), std::nullopt);
  EXPECT_EQ(feed.at(0.7, Arrived(std::nullopt)), std::nullopt);
  ReceivedTargets bad;  // A malformed message still says the source is alive ...
  bad.messages = 1;
  bad.malformed = 1;
  EXPECT_EQ(feed.at(0.8, bad), 150.0);  // ... and the last good target is followed again.
  EXPECT_EQ(feed.at(0.9, Arrived(140.0)), 140.0);
  EXPECT_EQ(feed.vented_frames(), 2);
  EXPECT_THAT(feed.notes().back(), HasSubstr("went silent 1 times for more than 0.5 s"));
}

}  // namespace
}  // namespace softsight
