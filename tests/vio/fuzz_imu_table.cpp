// libFuzzer target: IMU tables of other layouts (imu_table.hpp) and RTKLIB time-tag files
// (rtklib_time_tag.hpp). Byte 0 selects the time kind, bytes 1-2 (little endian) the length of a
// time-tag file that follows; the rest is the table. Any exception other than gvins::ParseError,
// or any crash/hang, is a bug.
#include <algorithm>
#include <cstdint>
#include <optional>
#include <string_view>

#include "gvins/base/parse_error.hpp"
#include "gvins/vio/imu_table.hpp"
#include "gvins/vio/rtklib_time_tag.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace gvins::vio;
  if (size < 3) return 0;
  const std::string_view all(reinterpret_cast<const char*>(data), size);
  const std::size_t tagBytes = std::min<std::size_t>(size - 3, data[1] | (std::size_t{data[2]} << 8));
  ImuTableFormat f;
  f.time = static_cast<ImuTimeKind>(data[0] % 4);
  if (data[0] & 4) f.columns = parseImuColumns("ax,ay,az,gx,gy,gz,t");
  try {
    std::optional<RtklibTimeTag> tag;
    if (tagBytes > 0) tag = RtklibTimeTag::parse(all.substr(3, tagBytes), "imu.csv.tag");
    if (tag) (void)tag->writtenBy(data[0]);
    parseImuTable(all.substr(3 + tagBytes), "imu.csv", f, tag ? &*tag : nullptr);
  } catch (const gvins::ParseError&) {
  }
  return 0;
}
