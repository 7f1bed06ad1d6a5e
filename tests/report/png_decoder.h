// A minimal PNG decoder for tests that look at screenshots: 8-bit
// grayscale, gray+alpha, RGB and RGBA, not interlaced (what headless
// Chromium writes). Inflates with zlib and undoes the five scanline filters.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbopt::report::testing {

struct RgbImage {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // width * height * 3, row-major
};

// Decodes `bytes`. Returns an empty string on success, else what is wrong.
std::string DecodePng(const std::string& bytes, RgbImage& image);

// Fraction of pixels that are not white (any channel below `threshold`).
double NonWhiteFraction(const RgbImage& image, int threshold = 250);

// Encodes RGB pixels as a PNG with the None filter (for testing the decoder).
std::string EncodePngForTest(const RgbImage& image);

}  // namespace mbopt::report::testing
