// Headless Chromium for tests that look at a page as a person would: a
// screenshot or the parsed DOM, with the browser's console log. Debian's
// package (installed by deploy/install-deps.sh) at /usr/bin/chromium, or
// $MBOPT_CHROMIUM.
#pragma once

#include <filesystem>
#include <string>

#include "tests/report/png_decoder.h"

namespace mbopt::report::testing {

std::string ChromiumPath();

// Runs Chromium on `page` with a fresh profile in `work_dir` and `action`
// (e.g. --dump-dom or --screenshot=FILE) in a window of the given size.
// Returns system()'s status; stdout and stderr (the console log) are left in
// work_dir/<name>.out and work_dir/<name>.err.
int RunHeadlessChromium(const std::filesystem::path& work_dir, const std::string& action,
                        const std::string& name, const std::filesystem::path& page, int width_px,
                        int height_px);

// Pixels whose channels are each within `tolerance` of (r, g, b).
int CountPixelsNear(const RgbImage& image, int r, int g, int b, int tolerance);

// The whole file as bytes ("" if unreadable).
std::string ReadWholeFile(const std::filesystem::path& path);

}  // namespace mbopt::report::testing
