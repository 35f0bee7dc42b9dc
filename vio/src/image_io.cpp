#include "gvins/vio/image_io.hpp"

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <vector>

#if GVINS_HAVE_LIBDEFLATE
#include <libdeflate.h>
#else
#include <zlib.h>
#endif

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
[[noreturn]] void corrupt(const std::string& name, const std::string& what) {
  fail(name, "unreadable image (corrupt or truncated): " + what);
}

std::uint32_t crc32Of(const std::uint8_t* p, std::size_t n) {
#if GVINS_HAVE_LIBDEFLATE
  return libdeflate_crc32(0, p, n);
#else
  return static_cast<std::uint32_t>(crc32(0L, p, static_cast<uInt>(n)));
#endif
}

// zlib stream -> exactly out.size() bytes; false if corrupt, short or too long.
bool inflateExactly(std::span<const std::uint8_t> in, std::span<std::uint8_t> out) {
#if GVINS_HAVE_LIBDEFLATE
  struct Free {
    void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
  };
  thread_local const std::unique_ptr<libdeflate_decompressor, Free> d(libdeflate_alloc_decompressor());
  if (!d) throw std::bad_alloc();
  std::size_t got = 0;
  const libdeflate_result r = libdeflate_zlib_decompress(d.get(), in.data(), in.size(), out.data(), out.size(), &got);
  return r == LIBDEFLATE_SUCCESS && got == out.size();
#else
  z_stream z{};
  if (inflateInit(&z) != Z_OK) throw std::bad_alloc();
  z.next_in = const_cast<Bytef*>(in.data());
  z.avail_in = static_cast<uInt>(in.size());
  z.next_out = out.data();
  z.avail_out = static_cast<uInt>(out.size());
  const int r = inflate(&z, Z_FINISH);
  const bool ok = r == Z_STREAM_END && z.total_out == out.size();
  inflateEnd(&z);
  return ok;
#endif
}

// Undoes the PNG row filters (PNG specification, 2nd edition, section 9.2) of an 8-bit single
// channel image: raw holds height rows of (filter byte, width bytes).
bool unfilterGray8(const std::uint8_t* raw, int width, int height, cv::Mat& out) {
  const auto w = static_cast<std::size_t>(width);
  thread_local std::vector<std::uint8_t> zeros;
  zeros.assign(w, 0);
  const std::uint8_t* up = zeros.data();
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* s = raw + static_cast<std::size_t>(y) * (w + 1);
    const std::uint8_t filter = *s++;
    std::uint8_t* d = out.ptr<std::uint8_t>(y);
    switch (filter) {
      case 0:  // None
        std::memcpy(d, s, w);
        break;
      case 1: {  // Sub
        std::uint8_t a = 0;
        for (std::size_t x = 0; x < w; ++x) d[x] = a = static_cast<std::uint8_t>(s[x] + a);
        break;
      }
      case 2:  // Up
        for (std::size_t x = 0; x < w; ++x) d[x] = static_cast<std::uint8_t>(s[x] + up[x]);
        break;
      case 3: {  // Average
        unsigned a = 0;
        for (std::size_t x = 0; x < w; ++x) d[x] = static_cast<std::uint8_t>(a = (s[x] + ((a + up[x]) >> 1)) & 0xffu);
        break;
      }
      case 4: {  // Paeth
        // The predictor (the one of left a, up b, up-left c closest to a + b - c; ties a, b, c)
        // in an equivalent form with a short dependency chain on a, branch-free: with
        // lo/hi = min/max(a, b) and t = 3c - a - b it is hi if t <= lo, else lo if hi <= t,
        // else c (checked against the definition for all 2^24 (a, b, c)).
        int a = 0, c = 0;
        for (std::size_t x = 0; x < w; ++x) {
          const int b = up[x];
          const int t = 3 * c - a - b;
          const int lo = std::min(a, b), hi = std::max(a, b);
          const int m0 = -static_cast<int>(hi <= t), m1 = -static_cast<int>(t <= lo);
          const int pred = (hi & m1) | (((lo & m0) | (c & ~m0)) & ~m1);
          a = (s[x] + pred) & 0xff;
          d[x] = static_cast<std::uint8_t>(a);
          c = b;
        }
        break;
      }
      default:
        return false;
    }
    up = d;
  }
  return true;
}

// 8-bit grey, non-interlaced PNGs (EuRoC's and gvins-sim's) without libpng: the chunks are
// walked here (critical chunks CRC-checked), the image data inflated in one call (libdeflate
// when built with it, else zlib) and unfiltered into the output. nullopt for every other kind
// of PNG (colour, palette, 16 bit, interlaced), which cv::imdecode handles.
std::optional<cv::Mat> decodeGray8Png(std::span<const std::uint8_t> b, const std::string& name) {
  // Signature (8), IHDR: length(4) "IHDR"(4) width(4) height(4) depth colour compression filter
  // interlace (1 each) CRC(4); checked by the caller up to the size.
  if (be32(b.data() + 8) != 13) corrupt(name, "IHDR chunk length");
  const std::uint8_t* ihdr = b.data() + 16;
  const std::uint8_t depth = ihdr[8], colour = ihdr[9], compression = ihdr[10], filterMethod = ihdr[11], interlace = ihdr[12];
  if (depth != 8 || colour != 0 || compression != 0 || filterMethod != 0 || interlace != 0) return std::nullopt;
  if (crc32Of(b.data() + 12, 17) != be32(b.data() + 29)) corrupt(name, "IHDR CRC");
  const int width = static_cast<int>(be32(ihdr)), height = static_cast<int>(be32(ihdr + 4));

  thread_local std::vector<std::uint8_t> idat, raw;
  idat.clear();
  bool end = false;
  for (std::size_t o = 33; !end;) {
    if (b.size() - o < 12) corrupt(name, "chunk header at byte " + std::to_string(o));
    const std::size_t len = be32(b.data() + o);
    if (len > b.size() - o - 12) corrupt(name, "chunk at byte " + std::to_string(o) + " runs past the end of the file");
    const std::uint8_t* type = b.data() + o + 4;
    const std::uint8_t* data = type + 4;
    const bool isIdat = std::memcmp(type, "IDAT", 4) == 0;
    end = std::memcmp(type, "IEND", 4) == 0;
    if ((type[0] & 0x20) == 0) {  // critical chunk (upper-case first letter): check its CRC
      if (crc32Of(type, len + 4) != be32(data + len)) corrupt(name, "CRC of chunk at byte " + std::to_string(o));
      if (!isIdat && !end) corrupt(name, "unexpected critical chunk at byte " + std::to_string(o));
    }
    if (isIdat) idat.insert(idat.end(), data, data + len);
    o += 12 + len;
  }
  const std::size_t rawSize = static_cast<std::size_t>(height) * (static_cast<std::size_t>(width) + 1);
  // Deflate expands by at most 1032:1; a header promising more than that is corrupt (and would
  // only make us allocate).
  if (idat.empty() || rawSize / 1032 > idat.size()) corrupt(name, "image data shorter than the header's size");
  raw.resize(rawSize);
  if (!inflateExactly(idat, raw)) corrupt(name, "image data do not inflate to " + std::to_string(width) + "x" + std::to_string(height));
  cv::Mat img(height, width, CV_8UC1);
  if (!unfilterGray8(raw.data(), width, height, img)) corrupt(name, "unknown PNG row filter");
  return img;
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
    if (auto img = decodeGray8Png(bytes, name)) return std::move(*img);
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
  thread_local std::vector<std::uint8_t> bytes;  // reused: no fresh pages per image
  bytes.resize(static_cast<std::size_t>(size));
  in.seekg(0);
  if (size > 0 && !in.read(reinterpret_cast<char*>(bytes.data()), size)) {
    throw ParseError(path, 0, "image", "read error");
  }
  return decodeGrayImage(bytes, path, ew, eh);
}

}  // namespace gvins::vio
