#include "gui/live_view.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>

#include "gui/live_controller.h"

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

namespace {

constexpr double kHelpScale = 0.42;
constexpr int kHelpLine = 17;    // px between lines at kHelpScale.
constexpr int kHelpKeyColumn = 58;  // px for the key names at kHelpScale.
constexpr int kHelpMargin = 8;

std::string KeyName(int key) {
  switch (key) {
    case 0:
      return "mouse";
    case ' ':
      return "space";
    default:
      return std::string(1, static_cast<char>(key));
  }
}

}  // namespace

int HelpPanelWidth() {
  int width = 0, baseline = 0;
  for (const LiveKey& k : kLiveKeys) {
    width = std::max(width, cv::getTextSize(k.what, kFont, kHelpScale, 1, &baseline).width);
  }
  return 2 * kHelpMargin + kHelpKeyColumn + width;
}

void DrawHelpPanel(cv::Mat& panel) {
  panel.setTo(cv::Scalar(24, 24, 24));
  const int lines = static_cast<int>(kLiveKeys.size()) + 1;
  // Shrink the text when the panel is lower than the list (a small frame on a small screen).
  const double fit = std::min(1.0, (panel.rows - 2.0 * kHelpMargin) / (kHelpLine * lines));
  const double scale = kHelpScale * fit;
  const int line = std::max(6, cvRound(kHelpLine * fit));
  int y = kHelpMargin + line;
  cv::putText(panel, "keys (h hides)", {kHelpMargin, y}, kFont, scale, cv::Scalar(120, 220, 255), 1,
              cv::LINE_AA);
  for (const LiveKey& k : kLiveKeys) {
    y += line;
    cv::putText(panel, KeyName(k.key), {kHelpMargin, y}, kFont, scale, cv::Scalar(120, 220, 255),
                1, cv::LINE_AA);
    cv::putText(panel, k.what, {kHelpMargin + cvRound(kHelpKeyColumn * fit), y}, kFont, scale,
                cv::Scalar(235, 235, 235), 1, cv::LINE_AA);
  }
}

}  // namespace softsight
