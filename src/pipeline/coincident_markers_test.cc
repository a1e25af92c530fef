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

// A decoding error turned part of a frame's colours: the red base marker looked blue, the blue
// tracker (lost a frame before) re-acquired it, while red itself was not found.
TEST(MarkersOnAMissingMarkersPlace, AMarkerFoundWhereAMissingOneJustWasIsDropped) {
  EXPECT_THAT(FindMarkersOnAMissingMarkersPlace({Lost(), At(221.6, 321.0), Lost()},
                                                {cv::Point2d(222.3, 321.0),
                                                 cv::Point2d(286.3, 223.0), std::nullopt}),
              ElementsAre(1u));
  // Without a recent position of its own (re-acquired after a long loss) it is dropped too.
  EXPECT_THAT(FindMarkersOnAMissingMarkersPlace({Lost(), At(221.6, 321.0)},
                                                {cv::Point2d(222.3, 321.0), std::nullopt}),
              ElementsAre(1u));
}

TEST(MarkersOnAMissingMarkersPlace, FoundMarkersAndDistantOnesAreKept) {
  // The other marker is found (that case is FindCoincidentMarkers'), or was elsewhere.
  EXPECT_THAT(FindMarkersOnAMissingMarkersPlace({At(0, 0), At(0.5, 0)},
                                                {cv::Point2d(0, 0), std::nullopt}),
              IsEmpty());
  EXPECT_THAT(FindMarkersOnAMissingMarkersPlace({Lost(), At(30, 0)},
                                                {cv::Point2d(0, 0), cv::Point2d(28, 0)}),
              IsEmpty());
  // A marker still at its own recent position keeps it whatever the other's record says.
  EXPECT_THAT(FindMarkersOnAMissingMarkersPlace({Lost(), At(5, 5)},
                                                {cv::Point2d(5, 5), cv::Point2d(5.5, 5)}),
              IsEmpty());
}

}  // namespace
}  // namespace softsight
