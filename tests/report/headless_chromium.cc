#include "tests/report/headless_chromium.h"

#include <cstdlib>
#include <fstream>
#include <sstream>

namespace mbopt::report::testing {

std::string ChromiumPath() {
  const char* env = std::getenv("MBOPT_CHROMIUM");
  return env != nullptr && *env != '\0' ? env : "/usr/bin/chromium";
}

int RunHeadlessChromium(const std::filesystem::path& work_dir, const std::string& action,
                        const std::string& name, const std::filesystem::path& page, int width_px,
                        int height_px) {
  const std::filesystem::path profile = work_dir / ("profile-" + name);
  const std::string command =
      "timeout 120 " + ChromiumPath() +
      " --headless --no-sandbox --disable-gpu --disable-quic --no-first-run"
      " --disable-background-networking --disable-component-update --disable-sync"
      " --hide-scrollbars --enable-logging=stderr --v=0"
      " --user-data-dir=" + profile.string() + " --window-size=" + std::to_string(width_px) + "," +
      std::to_string(height_px) + " " + action + " file://" + page.string() + " >" +
      (work_dir / (name + ".out")).string() + " 2>" + (work_dir / (name + ".err")).string();
  return std::system(command.c_str());
}

int CountPixelsNear(const RgbImage& image, int r, int g, int b, int tolerance) {
  int n = 0;
  for (std::size_t i = 0; i + 2 < image.rgb.size(); i += 3) {
    if (std::abs(image.rgb[i] - r) <= tolerance && std::abs(image.rgb[i + 1] - g) <= tolerance &&
        std::abs(image.rgb[i + 2] - b) <= tolerance) {
      ++n;
    }
  }
  return n;
}

std::string ReadWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace mbopt::report::testing
