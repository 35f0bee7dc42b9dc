// A deliberately minimal RTCM 3 frame scanner for the tests, written independently of the
// library's Framer (bitwise CRC, no buffering): the reference the library's counts are checked
// against.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

namespace gvins::rtcm::testing {

inline std::vector<std::uint8_t> readBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline std::filesystem::path dataDir() { return std::filesystem::path(GVINS_TEST_DATA); }

/// CRC-24Q bit by bit (polynomial 0x1864CFB, RTCM 10403.3 section 4.2).
inline std::uint32_t bitwiseCrc24q(const std::uint8_t* p, std::size_t n) {
  std::uint32_t crc = 0;
  for (std::size_t i = 0; i < n; ++i) {
    crc ^= static_cast<std::uint32_t>(p[i]) << 16;
    for (int b = 0; b < 8; ++b) {
      crc <<= 1;
      if (crc & 0x1000000u) crc ^= 0x1864CFBu;
    }
  }
  return crc & 0xFFFFFFu;
}

struct ScanResult {
  std::map<int, std::int64_t> types;  // message number -> frames
  std::int64_t frames = 0;
  std::int64_t badCandidates = 0;  // 0xD3 + zero reserved bits + complete length, CRC wrong
};

/// Walks the bytes: at every 0xD3 whose reserved bits are zero and whose frame fits, checks the
/// CRC; a good frame is counted and skipped whole, anything else advances one byte.
inline ScanResult independentScan(const std::vector<std::uint8_t>& d) {
  ScanResult r;
  std::size_t i = 0;
  while (i < d.size()) {
    if (d[i] == 0xD3 && i + 3 <= d.size() && (d[i + 1] >> 2) == 0) {
      const std::size_t len = (static_cast<std::size_t>(d[i + 1] & 3) << 8) | d[i + 2];
      if (i + len + 6 <= d.size()) {
        const std::uint32_t want = (static_cast<std::uint32_t>(d[i + len + 3]) << 16) |
                                   (static_cast<std::uint32_t>(d[i + len + 4]) << 8) | d[i + len + 5];
        if (bitwiseCrc24q(&d[i], len + 3) == want) {
          const int type = len >= 2 ? (d[i + 3] << 4) | (d[i + 4] >> 4) : -1;
          ++r.types[type];
          ++r.frames;
          i += len + 6;
          continue;
        }
        ++r.badCandidates;
      }
    }
    ++i;
  }
  return r;
}

/// Every file under tests/data/rtcm (recursively), sorted.
inline std::vector<std::filesystem::path> rtcmFiles() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::recursive_directory_iterator(dataDir() / "rtcm")) {
    if (e.is_regular_file()) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace gvins::rtcm::testing
