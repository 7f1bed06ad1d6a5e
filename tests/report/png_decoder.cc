#include "tests/report/png_decoder.h"

#include <zlib.h>

#include <cstdlib>
#include <string>
#include <vector>

namespace mbopt::report::testing {
namespace {

constexpr char kSignature[] = "\x89PNG\r\n\x1a\n";

std::uint32_t ReadU32(const std::string& s, std::size_t pos) {
  return (static_cast<std::uint32_t>(static_cast<std::uint8_t>(s[pos])) << 24) |
         (static_cast<std::uint32_t>(static_cast<std::uint8_t>(s[pos + 1])) << 16) |
         (static_cast<std::uint32_t>(static_cast<std::uint8_t>(s[pos + 2])) << 8) |
         static_cast<std::uint32_t>(static_cast<std::uint8_t>(s[pos + 3]));
}

void AppendU32(std::string& s, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) s += static_cast<char>((v >> shift) & 0xff);
}

void AppendChunk(std::string& png, const char* type, const std::string& data) {
  AppendU32(png, static_cast<std::uint32_t>(data.size()));
  std::string body = std::string(type, 4) + data;
  png += body;
  AppendU32(png, static_cast<std::uint32_t>(
                     crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()))));
}

int Paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return a;
  if (pb <= pc) return b;
  return c;
}

}  // namespace

std::string DecodePng(const std::string& bytes, RgbImage& image) {
  if (bytes.size() < 8 || bytes.compare(0, 8, std::string(kSignature, 8)) != 0) return "not a PNG signature";
  std::size_t pos = 8;
  int width = 0, height = 0, depth = 0, color = -1, interlace = 0;
  std::string idat;
  bool seen_end = false;
  while (pos + 12 <= bytes.size()) {
    const std::uint32_t length = ReadU32(bytes, pos);
    if (pos + 12 + length > bytes.size()) return "truncated chunk";
    const std::string type = bytes.substr(pos + 4, 4);
    const std::size_t data = pos + 8;
    if (type == "IHDR") {
      if (length < 13) return "short IHDR";
      width = static_cast<int>(ReadU32(bytes, data));
      height = static_cast<int>(ReadU32(bytes, data + 4));
      depth = static_cast<std::uint8_t>(bytes[data + 8]);
      color = static_cast<std::uint8_t>(bytes[data + 9]);
      interlace = static_cast<std::uint8_t>(bytes[data + 12]);
    } else if (type == "IDAT") {
      idat.append(bytes, data, length);
    } else if (type == "IEND") {
      seen_end = true;
      break;
    }
    pos += 12 + length;
  }
  if (!seen_end) return "no IEND chunk";
  if (width <= 0 || height <= 0 || width > 20000 || height > 20000) return "bad size";
  if (depth != 8) return "bit depth " + std::to_string(depth) + " not supported";
  if (interlace != 0) return "interlaced PNG not supported";
  int channels = 0;
  switch (color) {
    case 0: channels = 1; break;
    case 2: channels = 3; break;
    case 4: channels = 2; break;
    case 6: channels = 4; break;
    default: return "colour type " + std::to_string(color) + " not supported";
  }
  const std::size_t stride = static_cast<std::size_t>(width) * static_cast<std::size_t>(channels);
  std::vector<std::uint8_t> raw((stride + 1) * static_cast<std::size_t>(height));
  uLongf raw_size = static_cast<uLongf>(raw.size());
  const int z = uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(idat.data()),
                           static_cast<uLong>(idat.size()));
  if (z != Z_OK) return "zlib uncompress failed with code " + std::to_string(z);
  if (raw_size != raw.size()) return "image data has the wrong size";

  std::vector<std::uint8_t> previous(stride, 0), current(stride, 0);
  image.width = width;
  image.height = height;
  image.rgb.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 3, 0);
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* line = raw.data() + static_cast<std::size_t>(y) * (stride + 1);
    const int filter = line[0];
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= static_cast<std::size_t>(channels) ? current[i - channels] : 0;
      const int b = previous[i];
      const int c = i >= static_cast<std::size_t>(channels) ? previous[i - channels] : 0;
      int predictor = 0;
      switch (filter) {
        case 0: predictor = 0; break;
        case 1: predictor = a; break;
        case 2: predictor = b; break;
        case 3: predictor = (a + b) / 2; break;
        case 4: predictor = Paeth(a, b, c); break;
        default: return "unknown filter " + std::to_string(filter) + " on row " + std::to_string(y);
      }
      current[i] = static_cast<std::uint8_t>((line[1 + i] + predictor) & 0xff);
    }
    for (int x = 0; x < width; ++x) {
      const std::uint8_t* p = current.data() + static_cast<std::size_t>(x) * channels;
      std::uint8_t* out = image.rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3;
      if (channels <= 2) {
        out[0] = out[1] = out[2] = p[0];
      } else {
        out[0] = p[0];
        out[1] = p[1];
        out[2] = p[2];
      }
    }
    std::swap(previous, current);
  }
  return "";
}

double NonWhiteFraction(const RgbImage& image, int threshold) {
  const std::size_t pixels = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  if (pixels == 0) return 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < pixels; ++i) {
    const std::uint8_t* p = image.rgb.data() + 3 * i;
    if (p[0] < threshold || p[1] < threshold || p[2] < threshold) ++count;
  }
  return static_cast<double>(count) / static_cast<double>(pixels);
}

std::string EncodePngForTest(const RgbImage& image) {
  // Row y uses filter y % 5, so that a round trip exercises all five.
  const std::size_t stride = static_cast<std::size_t>(image.width) * 3;
  std::string raw;
  for (int y = 0; y < image.height; ++y) {
    const int filter = y % 5;
    raw += static_cast<char>(filter);
    const std::uint8_t* line = image.rgb.data() + static_cast<std::size_t>(y) * stride;
    const std::uint8_t* above = y > 0 ? line - stride : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= 3 ? line[i - 3] : 0;
      const int b = above != nullptr ? above[i] : 0;
      const int c = (i >= 3 && above != nullptr) ? above[i - 3] : 0;
      const int predictor = filter == 0 ? 0 : filter == 1 ? a : filter == 2 ? b : filter == 3 ? (a + b) / 2 : Paeth(a, b, c);
      raw += static_cast<char>((line[i] - predictor) & 0xff);
    }
  }
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string compressed(size, '\0');
  compress(reinterpret_cast<Bytef*>(compressed.data()), &size, reinterpret_cast<const Bytef*>(raw.data()),
           static_cast<uLong>(raw.size()));
  compressed.resize(size);
  std::string header;
  AppendU32(header, static_cast<std::uint32_t>(image.width));
  AppendU32(header, static_cast<std::uint32_t>(image.height));
  header += std::string("\x08\x02\x00\x00\x00", 5);
  std::string png(kSignature, 8);
  AppendChunk(png, "IHDR", header);
  AppendChunk(png, "IDAT", compressed);
  AppendChunk(png, "IEND", "");
  return png;
}

}  // namespace mbopt::report::testing
