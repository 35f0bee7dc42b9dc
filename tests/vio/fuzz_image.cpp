// libFuzzer target: image decoding (PNG/JPEG signature check, header size check, OpenCV decode).
// Any exception other than gvins::ParseError is a bug.
#include <cstdint>
#include <span>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/image_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    const cv::Mat img = gvins::vio::decodeGrayImage(std::span<const std::uint8_t>(data, size), "image.png");
    if (img.type() != CV_8UC1) __builtin_trap();
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
