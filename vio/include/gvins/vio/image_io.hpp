// Loading camera images as 8-bit grayscale with clear errors. Only PNG and JPEG are accepted
// (checked from the file signature), the header's size is checked against the expected
// resolution before decoding, and anything OpenCV cannot decode is a gvins::ParseError naming
// the file.
#pragma once

#include <cstdint>
#include <span>
#include <string>

#include <opencv2/core/mat.hpp>

namespace gvins::vio {

/// Decodes an image held in memory. expectedWidth/Height of 0 skip the size check; images
/// larger than 100 megapixels are refused. Colour images are converted to gray; 16-bit images
/// are scaled to 8 bits.
cv::Mat decodeGrayImage(std::span<const std::uint8_t> bytes, const std::string& name, int expectedWidth = 0,
                        int expectedHeight = 0);

/// Reads and decodes an image file (as decodeGrayImage).
cv::Mat readGrayImage(const std::string& path, int expectedWidth = 0, int expectedHeight = 0);

}  // namespace gvins::vio
