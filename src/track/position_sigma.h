// The standard uncertainty of a reported marker position: Observation::sigma_px, the CSV's
// `<marker>_sigma_px`. One number per position, the 1-sigma error along each image axis, so a
// reader can weigh positions (the stereo triangulation does) and "found" is a number: a found
// marker lies within 3 sigma of its true centre (measured: docs/measurements.md, "Uncertainty").
//
// The error of a centroid has a part that noise makes (it shrinks with the marker's size and its
// contrast) and a part that no amount of averaging removes: what the segmentation or the match
// takes for the marker is not exactly the marker (a domed marker's shaded flank, the soft band's
// levels, the template's surroundings changing with the pose). The second part grows with the
// marker's size and dominates on real footage; its constants are calibrated on the scenes with
// truth (rendered, physically rendered and real; see tests/real/check_real.py's coverage).
#pragma once

namespace softsight {

// What a blob's segmentation tells about how well its centroid is placed.
struct BlobEvidence {
  double area_px = 0;          // The blob's area.
  double noise_levels = 0;     // RMS spread of the marker's and its surroundings' levels.
  double contrast_levels = 0;  // Marker against surroundings, same units (0: unknown).
  // How much more asymmetric the blob is than the marker when whole (a part covered, cut, or
  // smeared by motion), px.
  double excess_asymmetry_px = 0;
  // How far the blob's centroid lies from the centre of its smallest enclosing circle, px: about
  // 0 for a whole disc, ellipse or any shape symmetric about its centre, as markers are. A blob
  // learned asymmetric (a dome whose lit top the range left out, a crescent of a marker whose top
  // the exposure clipped to white) has its centre somewhere between the two, whatever the model.
  double own_asymmetry_px = 0;
  bool rim_placed = false;     // The centre is a circle fitted to part of the rim.
  // How far the reported (soft) centroid lies from the mask's own (binary) one, px. On a flat
  // printed dot both agree to a few hundredths; where they part, what is marker and what is not
  // is uncertain at the rim (a lit dome's pale flank, its shaded one outside the hue range), and
  // the truth is about as far from either.
  double centroid_disagreement_px = 0;
  // How far the marker's centre moves between the channels it stands out in (a template's blob
  // in its matched channel and in its chromaticity), px: a bias no frame averages away.
  double definition_spread_px = 0;
  // How far the centroid moves when the blob takes in the pale fringe just outside its range
  // (ColourBlob::fringe_shift_px), px. A colour blob's soft centroid may have taken in the part
  // beyond its soft band (ColourBlob::fringe_placed); the edge may still lie anywhere between
  // the two cuts, which half of this covers.
  double fringe_shift_px = 0;
};

// Per axis, px: a colour blob's (or a template's blob's) centroid.
double BlobCentroidSigmaPx(const BlobEvidence& blob);

// Per axis, px: a template match's position, from its correlation with the first template
// (`zncc`, 1 = identical), the template's size and, when the position was put on the template's
// blob, that blob's evidence (area 0: no blob).
double TemplateMatchSigmaPx(double zncc, double template_width_px, double template_height_px,
                            const BlobEvidence& blob);

}  // namespace softsight
