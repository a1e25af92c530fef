// Drawing of the live window's own layer over the annotated frame: the status lines at the
// bottom and the key help. Drawing only: the controller decides what to show. Internal to gui.
#pragma once

#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace softsight {

// The lines at the bottom of the image, the first (the state line) in red when `first_red`
// (recording).
void DrawStatusLines(cv::Mat& top, const std::vector<std::string>& lines, bool first_red);

// The key list (kLiveKeys) as a compact panel beside the image (never over it, so no marker is
// hidden): the width it needs, and the drawing into `panel` (text shrinks if it is too low).
int HelpPanelWidth();
void DrawHelpPanel(cv::Mat& panel);

}  // namespace softsight
