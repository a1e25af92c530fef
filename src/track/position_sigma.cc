#include "track/position_sigma.h"

#include <algorithm>
#include <cmath>

namespace softsight {
namespace {

// Calibrated on the scenes with truth (see the header): the smallest constants with which at
// least 99 % of found positions lie within 3 sigma and none beyond 5 sigma on every scene.
constexpr double kFloorPx = 0.05;            // Quantisation and compression: any position.
constexpr double kBlobShapePerRadius = 0.04;  // Segmentation bias, per px of the blob's radius.
constexpr double kRimPlacedPerRadius = 0.10;  // A circle fitted to part of a rim.
constexpr double kAsymmetryShare = 0.5;       // Of the excess (or the blob's own) asymmetry.
constexpr double kDisagreementShare = 1.0;    // Of the soft and binary centroids' disagreement.
constexpr double kDefinitionShare = 0.5;      // Of the spread between channels (truth between).
constexpr double kFringeShare = 0.5;          // Of the pale fringe's pull on the centroid.
constexpr double kMatchShapePerSize = 0.02;   // A match's drift, per px of the template's half size.
constexpr double kMatchMisfitPerSize = 0.25;  // Per px of half size and unit of (1 - zncc).

double Radius(double area_px) { return std::sqrt(std::max(area_px, 0.0) / M_PI); }

// The part noise makes: each pixel of the soft band at the rim (about 2 pi r of them, at distance
// r) weighs with an error of noise / contrast, so the centroid moves by that over sqrt(pi r).
double NoiseSigmaPx(const BlobEvidence& blob) {
  const double r = Radius(blob.area_px);
  if (!(blob.contrast_levels > 0) || !(r > 0)) return 0.0;
  return blob.noise_levels / blob.contrast_levels / std::sqrt(M_PI * r);
}

}  // namespace

double BlobCentroidSigmaPx(const BlobEvidence& blob) {
  const double r = Radius(blob.area_px);
  const double shape = (blob.rim_placed ? kRimPlacedPerRadius : kBlobShapePerRadius) * r;
  const double noise = NoiseSigmaPx(blob);
  const double asymmetry =
      kAsymmetryShare * std::max({blob.excess_asymmetry_px, blob.own_asymmetry_px, 0.0});
  const double disagreement = kDisagreementShare * blob.centroid_disagreement_px;
  const double definition = kDefinitionShare * blob.definition_spread_px;
  const double fringe = kFringeShare * blob.fringe_shift_px;
  return std::sqrt(kFloorPx * kFloorPx + shape * shape + noise * noise + asymmetry * asymmetry +
                   disagreement * disagreement + definition * definition + fringe * fringe);
}

double TemplateMatchSigmaPx(double zncc, double template_width_px, double template_height_px,
                            const BlobEvidence& blob) {
  const double half = 0.5 * std::min(template_width_px, template_height_px);
  const double misfit = std::clamp(1.0 - zncc, 0.0, 1.0);
  const double drift = kMatchShapePerSize * half;
  const double match = kMatchMisfitPerSize * misfit * half;
  const double on_blob = blob.area_px > 0 ? BlobCentroidSigmaPx(blob) : kFloorPx;
  return std::sqrt(on_blob * on_blob + drift * drift + match * match);
}

}  // namespace softsight
