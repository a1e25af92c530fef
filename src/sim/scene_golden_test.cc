// The default scenes must render exactly as before the bench, distractors and plate existed:
// every accuracy figure in the README was measured on them. The hashes were taken from the
// renderer before those features were added (commit 0c1ef2b).
#include <cstdint>

#include <gtest/gtest.h>

#include "softsight/sim/scene.h"

namespace softsight {
namespace {

// FNV-1a over the pixel bytes, row by row.
uint64_t PixelHash(const cv::Mat& image) {
  uint64_t h = 0xcbf29ce484222325ull;
  for (int y = 0; y < image.rows; ++y) {
    const uchar* row = image.ptr<uchar>(y);
    for (size_t x = 0; x < image.cols * image.elemSize(); ++x) {
      h ^= row[x];
      h *= 0x100000001b3ull;
    }
  }
  return h;
}

uint64_t SceneHash(SceneKind kind, bool camera_effects) {
  SceneOptions o;
  o.kind = kind;
  o.size = cv::Size(320, 240);
  o.frame_count = 40;
  o.length_px = 150;
  o.width_px = 20;
  o.marker_radius_px = 6;
  NoiseOptions noise;
  std::vector<Occluder> occluders;
  if (camera_effects) {
    noise.sigma = 4;
    noise.blur_sigma_px = 0.8;
    noise.gain_end = 0.8;
    occluders.push_back({cv::Rect2d(100.3, 60.6, 40.5, 30.2), 10, 30, {90, 100, 110}});
  }
  SyntheticScene scene(o, noise, RenderOptions{}, occluders);
  uint64_t h = 0;
  cv::Mat image;
  for (int i : {0, 13, 20, 39}) h = h * 31 + PixelHash((scene.render(i, image), image));
  return h;
}

TEST(SceneGoldenTest, DefaultScenesRenderAsBefore) {
  struct Case {
    SceneKind kind;
    bool effects;
    uint64_t hash;
  };
  const Case cases[] = {
      {SceneKind::kBending, false, 0x7f93a4dc2de3991eull},
      {SceneKind::kWedge1, false, 0x82ec31aeb73f4ccull},
      {SceneKind::kWedge4, false, 0xc8c95436a2b0d988ull},
      {SceneKind::kBending, true, 0x19eacc47badab01aull},
  };
  for (const Case& c : cases) {
    const uint64_t h = SceneHash(c.kind, c.effects);
    EXPECT_EQ(h, c.hash) << SceneKindName(c.kind) << (c.effects ? " with camera effects" : "");
  }
}

}  // namespace
}  // namespace softsight
