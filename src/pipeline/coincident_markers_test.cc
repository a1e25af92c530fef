#include "pipeline/coincident_markers.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace softsight {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

MarkerObservation At(double x, double y) { return {"m", {cv::Point2d(x, y), 0.9}}; }
MarkerObservation Lost() { return {"m", {}}; }

TEST(CoincidentMarkers, DistinctMarkersAreKept) {
  EXPECT_THAT(FindCoincidentMarkers({At(0, 0), At(18, 0), Lost()},
                                    {cv::Point2d(0, 0), cv::Point2d(18, 0), std::nullopt}),
              IsEmpty());
}

TEST(CoincidentMarkers, TheMarkerThatJumpedOntoAnotherIsDropped) {
  // Marker 2 was lost (covered) and re-acquired onto marker 1's disc.
  EXPECT_THAT(FindCoincidentMarkers({At(0, 0), At(50, 50), At(50.4, 49.8)},
                                    {cv::Point2d(0, 0), cv::Point2d(50, 50), std::nullopt}),
              ElementsAre(2u));
  // Marker 0 was tracked elsewhere and jumped 40 px onto marker 1, which barely moved.
  EXPECT_THAT(FindCoincidentMarkers({At(50.5, 50), At(50, 50)},
                                    {cv::Point2d(10, 50), cv::Point2d(49, 50)}),
              ElementsAre(0u));
}

TEST(CoincidentMarkers, WithoutHistoryNeitherIsTrusted) {
  EXPECT_THAT(FindCoincidentMarkers({At(5, 5), At(6, 5)}, {std::nullopt, std::nullopt}),
              ElementsAre(0u, 1u));
}

TEST(CoincidentMarkers, LostMarkersNeverConflict) {
  EXPECT_THAT(FindCoincidentMarkers({Lost(), At(5, 5), Lost()},
                                    {cv::Point2d(5, 5), std::nullopt, cv::Point2d(5, 5)}),
              IsEmpty());
}

}  // namespace
}  // namespace softsight
