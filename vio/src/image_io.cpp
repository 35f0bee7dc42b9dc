#include "gvins/vio/image_io.hpp"

#include <cstring>
#include <fstream>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "gvins/base/parse_error.hpp"

namespace gvins::vio {
namespace {
constexpr std::uint8_t kPng[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr std::int64_t kMaxPixels = 100'000'000;

std::uint32_t be32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) | p[3];
}

[[noreturn]] void fail(const std::string& name, const std::string& what) { throw ParseError(name, 0, "image", what); }

void checkSize(const std::string& name, std::int64_t w, std::int64_t h, int ew, int eh) {
  if (w <= 0 || h <= 0 || w > kMaxPixels || h > kMaxPixels || w * h > kMaxPixels) {
    fail(name, "implausible image size " + std::to_string(w) + "x" + std::to_string(h));
  }
  if ((ew > 0 && w != ew) || (eh > 0 && h != eh)) {
    fail(name, "image is " + std::to_string(w) + "x" + std::to_string(h) + ", the calibration says " +
                   std::to_string(ew) + "x" + std::to_string(eh));
  }
}
}  // namespace

cv::Mat decodeGrayImage(std::span<const std::uint8_t> bytes, const std::string& name, int ew, int eh) {
  if (bytes.empty()) fail(name, "empty image file");
  const bool png = bytes.size() >= 8 && std::memcmp(bytes.data(), kPng, 8) == 0;
  const bool jpeg = bytes.size() >= 3 && bytes[0] == 0xFF && bytes[1] == 0xD8 && bytes[2] == 0xFF;
  if (!png && !jpeg) fail(name, "not a PNG or JPEG file");
  if (png) {
    // IHDR must be the first chunk: length(4) "IHDR"(4) width(4) height(4).
    if (bytes.size() < 33 || std::memcmp(bytes.data() + 12, "IHDR", 4) != 0) fail(name, "truncated PNG header");
    checkSize(name, be32(bytes.data() + 16), be32(bytes.data() + 20), ew, eh);
  }
  // cv::Mat header over the caller's bytes (imdecode does not modify its input).
  const cv::Mat buf(1, static_cast<int>(std::min<std::size_t>(bytes.size(), 0x7fffffff)), CV_8UC1,
                    const_cast<std::uint8_t*>(bytes.data()));
  cv::Mat img;
  try {
    img = cv::imdecode(buf, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    fail(name, std::string("cannot decode image: ") + e.what());
  }
  if (img.empty()) fail(name, "unreadable image (corrupt or truncated)");
  checkSize(name, img.cols, img.rows, ew, eh);
  if (img.depth() == CV_16U) {
    cv::Mat t;
    img.convertTo(t, CV_8U, 1.0 / 257.0);
    img = t;
  } else if (img.depth() != CV_8U) {
    fail(name, "unsupported pixel depth");
  }
  if (img.channels() == 3) {
    cv::Mat g;
    cv::cvtColor(img, g, cv::COLOR_BGR2GRAY);
    return g;
  }
  if (img.channels() == 4) {
    cv::Mat g;
    cv::cvtColor(img, g, cv::COLOR_BGRA2GRAY);
    return g;
  }
  if (img.channels() == 2) {  // gray + alpha
    cv::Mat g;
    cv::extractChannel(img, g, 0);
    return g;
  }
  return img;
}

cv::Mat readGrayImage(const std::string& path, int ew, int eh) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw ParseError(path, 0, "image", "cannot open image file");
  const std::streamoff size = in.tellg();
  if (size < 0 || size > (std::streamoff{1} << 30)) throw ParseError(path, 0, "image", "cannot read image file size");
  std::vector<std::uint8_t> bytes(static_cast<std::size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
    throw ParseError(path, 0, "image", "read error");
  }
  return decodeGrayImage(bytes, path, ew, eh);
}

}  // namespace gvins::vio
