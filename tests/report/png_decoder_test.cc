#include "tests/report/png_decoder.h"

#include <gtest/gtest.h>

namespace mbopt::report::testing {
namespace {

RgbImage Gradient(int width, int height) {
  RgbImage image;
  image.width = width;
  image.height = height;
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      image.rgb.push_back(static_cast<std::uint8_t>(x * 37 + y));
      image.rgb.push_back(static_cast<std::uint8_t>(255 - y * 11));
      image.rgb.push_back(static_cast<std::uint8_t>((x * y) & 0xff));
    }
  }
  return image;
}

TEST(PngDecoder, RoundTripsEveryFilterType) {
  const RgbImage original = Gradient(17, 11);  // rows use filters 0..4 in turn
  RgbImage decoded;
  ASSERT_EQ(DecodePng(EncodePngForTest(original), decoded), "");
  EXPECT_EQ(decoded.width, 17);
  EXPECT_EQ(decoded.height, 11);
  EXPECT_EQ(decoded.rgb, original.rgb);
}

TEST(PngDecoder, RejectsNonPngAndTruncatedData) {
  RgbImage image;
  EXPECT_NE(DecodePng("GIF89a", image), "");
  const std::string png = EncodePngForTest(Gradient(4, 4));
  EXPECT_NE(DecodePng(png.substr(0, png.size() - 20), image), "");
}

TEST(NonWhiteFraction, CountsInk) {
  RgbImage image;
  image.width = 4;
  image.height = 1;
  image.rgb = {255, 255, 255, 0, 0, 0, 255, 251, 255, 255, 200, 255};
  EXPECT_DOUBLE_EQ(NonWhiteFraction(image), 0.5);  // an exact ratio of counts
}

}  // namespace
}  // namespace mbopt::report::testing
