// The position's sigma grows with what makes a position less certain, each term on its own.
#include "track/position_sigma.h"

#include <gtest/gtest.h>

namespace softsight {
namespace {

BlobEvidence Disc(double radius_px) {
  BlobEvidence blob;
  blob.area_px = 3.14159265 * radius_px * radius_px;
  blob.noise_levels = 3;
  blob.contrast_levels = 120;
  return blob;
}

TEST(PositionSigma, ABlobsSigmaGrowsWithSizeNoisePartialViewAndARimFit) {
  const double base = BlobCentroidSigmaPx(Disc(8));
  EXPECT_GT(base, 0.05);  // Never below the floor...
  EXPECT_LT(base, 0.5);   // ... and well under a pixel for a clear, whole 16 px disc.
  EXPECT_GT(BlobCentroidSigmaPx(Disc(16)), base);
  BlobEvidence noisy = Disc(8);
  noisy.noise_levels = 60;
  noisy.contrast_levels = 20;
  EXPECT_GT(BlobCentroidSigmaPx(noisy), base + 0.1);
  BlobEvidence cut = Disc(8);
  cut.excess_asymmetry_px = 2;
  EXPECT_GT(BlobCentroidSigmaPx(cut), base + 0.5);
  BlobEvidence rim = Disc(8);
  rim.rim_placed = true;
  EXPECT_GT(BlobCentroidSigmaPx(rim), base);
}

TEST(PositionSigma, ABlobLearnedAsymmetricIsNoSurerForItsModelBeingSo) {
  // A crescent: a dome whose top the exposure clipped to white, its centroid 3 px from the centre
  // of its smallest enclosing circle. Learned so in its first frame, it is no more asymmetric than
  // its model (excess 0), but the marker's centre still lies somewhere between the two.
  const double base = BlobCentroidSigmaPx(Disc(8));
  BlobEvidence crescent = Disc(8);
  crescent.own_asymmetry_px = 3;
  EXPECT_GE(BlobCentroidSigmaPx(crescent), 1.5);
  // A whole disc's own asymmetry is the pixel grid's few tenths: its sigma barely moves.
  BlobEvidence whole = Disc(8);
  whole.own_asymmetry_px = 0.2;
  EXPECT_LT(BlobCentroidSigmaPx(whole), base + 0.05);
}

TEST(PositionSigma, ABlobsSigmaCoversTheSoftAndBinaryCentroidsDisagreement) {
  // A lit dome: its pale flank counts little in the soft centroid, its shaded one, outside the hue
  // range, counts in it alone; the two centroids part by 0.9 px and the truth lies about as far
  // (the physically rendered fast bend: 1.3-1.9 px from the soft one, 0.3-1.0 from the binary).
  const double base = BlobCentroidSigmaPx(Disc(8));
  BlobEvidence dome = Disc(8);
  dome.centroid_disagreement_px = 0.9;
  EXPECT_GE(BlobCentroidSigmaPx(dome), 0.9);
  // A flat printed dot's centroids agree to a few hundredths: its sigma barely moves.
  BlobEvidence dot = Disc(8);
  dot.centroid_disagreement_px = 0.03;
  EXPECT_LT(BlobCentroidSigmaPx(dot), base + 0.01);
}

TEST(PositionSigma, AMatchsSigmaGrowsAsTheMatchFitsLess) {
  const BlobEvidence none;
  const double good = TemplateMatchSigmaPx(0.99, 31, 31, none);
  EXPECT_GT(good, 0.05);
  EXPECT_LT(good, 0.5);
  EXPECT_GT(TemplateMatchSigmaPx(0.8, 31, 31, none), good + 0.3);
  EXPECT_GT(TemplateMatchSigmaPx(0.99, 61, 61, none), good);
  EXPECT_GE(TemplateMatchSigmaPx(0.99, 31, 31, Disc(8)), good);
}

}  // namespace
}  // namespace softsight
