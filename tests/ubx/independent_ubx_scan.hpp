// A deliberately minimal UBX frame scanner for the tests, written independently of the library's
// Framer (no buffering, checksum written out inline): the reference the library's counts are
// checked against. Same rule as the Framer: a good frame is counted and skipped whole, anything
// else advances one byte.
#pragma once

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <vector>

namespace gvins::ubx::testing {

inline std::vector<std::uint8_t> readBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

inline std::filesystem::path dataDir() { return std::filesystem::path(GVINS_TEST_DATA); }

struct ScanResult {
  std::map<int, std::int64_t> types;  // class << 8 | id -> frames
  std::int64_t frames = 0;
  std::int64_t badCandidates = 0;  // B5 62 + complete frame, checksum wrong
  std::vector<std::size_t> offsets;  // where each good frame starts
};

inline ScanResult independentScan(const std::vector<std::uint8_t>& d, std::size_t maxLen = 8192) {
  ScanResult r;
  std::size_t i = 0;
  while (i < d.size()) {
    if (d[i] == 0xB5 && i + 6 <= d.size() && d[i + 1] == 0x62) {
      const std::size_t len = d[i + 4] + 256u * d[i + 5];
      if (len <= maxLen && i + len + 8 <= d.size()) {
        unsigned a = 0, b = 0;
        for (std::size_t k = i + 2; k < i + 6 + len; ++k) {
          a = (a + d[k]) % 256;
          b = (b + a) % 256;
        }
        if (a == d[i + 6 + len] && b == d[i + 7 + len]) {
          ++r.types[d[i + 2] * 256 + d[i + 3]];
          ++r.frames;
          r.offsets.push_back(i);
          i += len + 8;
          continue;
        }
        ++r.badCandidates;
      }
    }
    ++i;
  }
  return r;
}

/// Builds one UBX frame around a payload (checksum computed here, independently of the library).
inline std::vector<std::uint8_t> makeFrame(std::uint8_t cls, std::uint8_t id,
                                           const std::vector<std::uint8_t>& payload) {
  std::vector<std::uint8_t> f(payload.size() + 6);
  f[0] = 0xB5;
  f[1] = 0x62;
  f[2] = cls;
  f[3] = id;
  f[4] = static_cast<std::uint8_t>(payload.size() & 0xFF);
  f[5] = static_cast<std::uint8_t>(payload.size() >> 8);
  std::copy(payload.begin(), payload.end(), f.begin() + 6);
  unsigned a = 0, b = 0;
  for (std::size_t k = 2; k < f.size(); ++k) {
    a = (a + f[k]) % 256;
    b = (b + a) % 256;
  }
  f.push_back(static_cast<std::uint8_t>(a));
  f.push_back(static_cast<std::uint8_t>(b));
  return f;
}

/// The UBX logs bundled under tests/data/ubx, sorted.
inline std::vector<std::filesystem::path> ubxFiles() {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dataDir() / "ubx")) {
    const auto ext = e.path().extension();
    if (e.is_regular_file() && (ext == ".log" || ext == ".ubx")) files.push_back(e.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace gvins::ubx::testing
