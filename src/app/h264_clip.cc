// softsight_h264_clip INPUT OUTPUT.mp4 [GOP]: re-encodes a video (any the program reads, e.g. one
// `softsight synth` rendered) as H.264 in MP4 with a key frame every GOP frames (default 250,
// FFmpeg's libx264 default, as a phone, a webcam's software or `ffmpeg -i x.avi y.mp4` writes it).
// For scripts/bench.sh (issue 45: `track` on H.264 beside a bare decode of the same file): OpenCV's
// writer has no H.264 key-frame interval setting in 4.6 (it writes a key frame every 12 frames),
// and Debian's OpenCV is all the project builds on. A benchmark tool: not installed, not tested.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>

#include "io/h264_writer.h"
#include "softsight/io/frame_source.h"

namespace {

int Main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: softsight_h264_clip INPUT OUTPUT.mp4 [GOP]\n";
    return 2;
  }
  const std::string output = argv[2];
  const int gop = argc > 3 ? std::atoi(argv[3]) : 250;
  std::unique_ptr<softsight::FrameSource> source = softsight::OpenFrameSource({argv[1], {}, 30.0});
  const double fps = source->fps().value_or(30.0);
  softsight::Frame frame;
  if (!source->read(frame)) throw std::runtime_error("no frames");
  // 4:2:0 chroma wants an even size: an odd last row or column is left out.
  const int w = frame.image.cols & ~1, h = frame.image.rows & ~1;

  softsight::H264WriterOptions options;
  options.size = {w, h};
  options.fps = static_cast<int>(fps + 0.5);
  options.gop = gop;
  options.crf = "20";
  softsight::H264Writer writer(output, options);
  do {
    writer.write(frame.image(cv::Rect(0, 0, w, h)));
  } while (source->read(frame));
  writer.finish();
  std::printf("%s: %lld frames %dx%d, H.264 (%s), a key frame every %d\n", output.c_str(),
              static_cast<long long>(writer.frames()), w, h, writer.encoder(), gop);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return Main(argc, argv);
  } catch (const std::exception& e) {
    std::cerr << "softsight_h264_clip: " << e.what() << "\n";
    return 1;
  }
}
