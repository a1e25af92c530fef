#include "gui/live_view.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "softsight/gui/live_controller.h"

namespace softsight {
namespace {
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
}  // namespace

void DrawStatusLines(cv::Mat& top, const std::vector<std::string>& lines, bool first_red) {
  const double scale = std::max(0.4, top.cols / 640.0 * 0.5);
  int y = top.rows - 10 - 22 * static_cast<int>(lines.size() - 1);
  for (const std::string& text : lines) {
    cv::putText(top, text, {8, y}, kFont, scale, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
    cv::putText(top, text, {8, y}, kFont, scale,
                first_red && &text == &lines.front() ? cv::Scalar(80, 80, 255)
                                                     : cv::Scalar(255, 255, 255),
                1, cv::LINE_AA);
    y += 22;
  }
}

void DrawLiveHelp(cv::Mat& top) {
  const cv::Size image_size = top.size();
  // The key list, scaled down until it fits the image, centred on a darkened block.
  std::vector<std::string> help;
  for (const LiveKey& k : kLiveKeys) {
    std::string text = k.key == ' ' ? "space  "
                       : k.key != 0 ? std::string(1, char(k.key)) + "  "
                                    : "";
    help.push_back(text + k.what);
  }
  double help_scale = 0.5;
  int baseline = 0, width = 0;
  for (const std::string& text : help) {
    width = std::max(width, cv::getTextSize(text, kFont, help_scale, 1, &baseline).width);
  }
  const int line_height_at_scale = 24;
  const double fit =
      std::min((image_size.width - 24.0) / width,
               (image_size.height - 16.0) / (line_height_at_scale * (help.size() + 0.5)));
  if (fit < 1.0) help_scale *= fit;
  const int line_height = std::max(8, cvRound(line_height_at_scale * help_scale / 0.5));
  const int block_w = cvRound(width * help_scale / 0.5) + 20;
  const int block_h = line_height * static_cast<int>(help.size()) + line_height / 2;
  const cv::Rect block = cv::Rect((image_size.width - block_w) / 2,
                                  (image_size.height - block_h) / 2, block_w, block_h) &
                         cv::Rect(0, 0, image_size.width, image_size.height);
  cv::Mat shade = top(block);
  shade.convertTo(shade, -1, 0.25, 0);
  int line_y = block.y + line_height;
  for (const std::string& text : help) {
    cv::putText(top, text, {block.x + 10, line_y}, kFont, help_scale, cv::Scalar(255, 255, 255),
                1, cv::LINE_AA);
    line_y += line_height;
  }
}

}  // namespace softsight
