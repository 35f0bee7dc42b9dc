// ROS 1 serialisation of the GVINS dataset messages; see rosbag_messages.hpp.
#include "gvins/fusion/rosbag_messages.hpp"

#include <bit>
#include <cstring>
#include <limits>
#include <type_traits>

#include "gvins/base/parse_error.hpp"

namespace gvins::fusion::ros {
namespace {

static_assert(std::endian::native == std::endian::little, "ROS serialisation is little-endian; big-endian hosts need byte swaps");

// ---- writing ---------------------------------------------------------------------------------
class Writer {
 public:
  template <class T>
  void pod(T v) {
    static_assert(std::is_arithmetic_v<T>);
    const auto* p = reinterpret_cast<const std::uint8_t*>(&v);
    out_.insert(out_.end(), p, p + sizeof(T));
  }
  void count(std::size_t n) {
    if (n > std::numeric_limits<std::uint32_t>::max()) throw std::length_error("ROS array longer than 2^32-1 elements");
    pod(static_cast<std::uint32_t>(n));
  }
  void str(const std::string& s) {
    count(s.size());
    out_.insert(out_.end(), s.begin(), s.end());
  }
  template <class T>
  void vec(const std::vector<T>& v) {
    count(v.size());
    for (T x : v) pod(x);
  }
  template <class T, std::size_t N>
  void fixed(const std::array<T, N>& a) {
    for (T x : a) pod(x);
  }
  void time(const Time& t) {
    pod(t.sec);
    pod(t.nsec);
  }
  void header(const Header& h) {
    pod(h.seq);
    time(h.stamp);
    str(h.frameId);
  }
  void gnssTime(const GnssTimeMsg& t) {
    pod(t.week);
    pod(t.tow);
  }
  std::vector<std::uint8_t> take() { return std::move(out_); }

 private:
  std::vector<std::uint8_t> out_;
};

// ---- reading ---------------------------------------------------------------------------------
class Reader {
 public:
  Reader(std::span<const std::uint8_t> b, std::string_view source, std::uint64_t base)
      : b_(b), source_(source), base_(base) {}

  [[noreturn]] void fail(const std::string& field, const std::string& why) const {
    throw ParseError(std::string(source_), static_cast<std::int64_t>(base_ + pos_), field, why);
  }
  void need(std::size_t n, const std::string& field) const {
    if (n > b_.size() - pos_)
      fail(field, "message ends after " + std::to_string(b_.size()) + " bytes; " + std::to_string(n) +
                      " more bytes needed at offset " + std::to_string(pos_) + " (wrong message layout or truncated)");
  }
  template <class T>
  T pod(const std::string& field) {
    need(sizeof(T), field);
    T v;
    std::memcpy(&v, b_.data() + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  std::size_t count(const std::string& field, std::size_t elementSize) {
    const auto n = pod<std::uint32_t>(field + " length");
    // A count can never exceed what is left: refuse before allocating.
    if (static_cast<std::uint64_t>(n) * elementSize > b_.size() - pos_) {
      pos_ -= 4;  // report the offset of the length field
      fail(field, "length " + std::to_string(n) + " exceeds the " + std::to_string(b_.size() - pos_) +
                      " bytes left in the message (wrong message layout or truncated)");
    }
    return n;
  }
  std::string str(const std::string& field) {
    const std::size_t n = count(field, 1);
    std::string s(reinterpret_cast<const char*>(b_.data() + pos_), n);
    pos_ += n;
    return s;
  }
  template <class T>
  std::vector<T> vec(const std::string& field) {
    const std::size_t n = count(field, sizeof(T));
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), b_.data() + pos_, n * sizeof(T));
    pos_ += n * sizeof(T);
    return v;
  }
  template <class T, std::size_t N>
  void fixed(std::array<T, N>& a, const std::string& field) {
    for (std::size_t i = 0; i < N; ++i) a[i] = pod<T>(field + "[" + std::to_string(i) + "]");
  }
  Time time(const std::string& field) {
    Time t;
    t.sec = pod<std::uint32_t>(field + ".sec");
    t.nsec = pod<std::uint32_t>(field + ".nsec");
    return t;
  }
  Header header() {
    Header h;
    h.seq = pod<std::uint32_t>("header.seq");
    h.stamp = time("header.stamp");
    h.frameId = str("header.frame_id");
    return h;
  }
  GnssTimeMsg gnssTime(const std::string& field) {
    GnssTimeMsg t;
    t.week = pod<std::uint32_t>(field + ".week");
    t.tow = pod<double>(field + ".tow");
    return t;
  }
  void end() const {
    if (pos_ != b_.size())
      fail("end of message", std::to_string(b_.size() - pos_) + " trailing bytes after the last field (wrong message layout)");
  }
  std::size_t pos() const { return pos_; }

 private:
  std::span<const std::uint8_t> b_;
  std::string_view source_;
  std::uint64_t base_;
  std::size_t pos_ = 0;
};

constexpr std::string_view kSep =
    "\n================================================================================\nMSG: ";

// Definitions as in the .msg files, comments left out.
constexpr std::string_view kHeaderDef = "uint32 seq\ntime stamp\nstring frame_id\n";
constexpr std::string_view kGnssTimeDef = "uint32 week\nfloat64 tow\n";

std::string withDeps(std::string_view body, std::initializer_list<std::pair<std::string_view, std::string_view>> deps) {
  std::string s(body);
  for (const auto& [name, text] : deps) {
    s += kSep;
    s += name;
    s += '\n';
    s += text;
  }
  return s;
}

}  // namespace

const MessageType& imuType() {
  static const std::string d = withDeps(
      "Header header\ngeometry_msgs/Quaternion orientation\nfloat64[9] orientation_covariance\n"
      "geometry_msgs/Vector3 angular_velocity\nfloat64[9] angular_velocity_covariance\n"
      "geometry_msgs/Vector3 linear_acceleration\nfloat64[9] linear_acceleration_covariance\n",
      {{"std_msgs/Header", kHeaderDef},
       {"geometry_msgs/Quaternion", "float64 x\nfloat64 y\nfloat64 z\nfloat64 w\n"},
       {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"}});
  static const MessageType t{"sensor_msgs/Imu", "6a62c6daae103f4ff57a132d6f95cec2", d};
  return t;
}

const MessageType& imageType() {
  static const std::string d = withDeps(
      "Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\nuint8[] data\n",
      {{"std_msgs/Header", kHeaderDef}});
  static const MessageType t{"sensor_msgs/Image", "060021388200f6f0f447d0fcd9c64743", d};
  return t;
}

const MessageType& compressedImageType() {
  static const std::string d =
      withDeps("Header header\nstring format\nuint8[] data\n", {{"std_msgs/Header", kHeaderDef}});
  static const MessageType t{"sensor_msgs/CompressedImage", "8f7a12909da2c9d3332d540a0977563f", d};
  return t;
}

namespace {
constexpr std::string_view kGnssObsDef =
    "GnssTimeMsg time\nuint32 sat\nfloat64[] freqs\nfloat64[] CN0\nuint8[] LLI\nuint8[] code\nfloat64[] psr\n"
    "float64[] psr_std\nfloat64[] cp\nfloat64[] cp_std\nfloat64[] dopp\nfloat64[] dopp_std\nuint8[] status\n";
}  // namespace

const MessageType& gnssMeasType() {
  static const std::string d = withDeps(
      "GnssObsMsg[] meas\n", {{"gnss_comm/GnssObsMsg", kGnssObsDef}, {"gnss_comm/GnssTimeMsg", kGnssTimeDef}});
  static const MessageType t{"gnss_comm/GnssMeasMsg", "0eafeb530a3e6637722c4e296734c119", d};
  return t;
}

const MessageType& gnssEphemType() {
  static const std::string d = withDeps(
      "uint32 sat\nGnssTimeMsg ttr\nGnssTimeMsg toe\nGnssTimeMsg toc\nfloat64 toe_tow\nuint32 week\nuint32 iode\n"
      "uint32 iodc\nuint32 health\nuint32 code\nfloat64 ura\nfloat64 A\nfloat64 e\nfloat64 i0\nfloat64 omg\n"
      "float64 OMG0\nfloat64 M0\nfloat64 delta_n\nfloat64 OMG_dot\nfloat64 i_dot\nfloat64 cuc\nfloat64 cus\n"
      "float64 crc\nfloat64 crs\nfloat64 cic\nfloat64 cis\nfloat64 af0\nfloat64 af1\nfloat64 af2\nfloat64 tgd0\n"
      "float64 tgd1\nfloat64 A_dot\nfloat64 n_dot\n",
      {{"gnss_comm/GnssTimeMsg", kGnssTimeDef}});
  static const MessageType t{"gnss_comm/GnssEphemMsg", "b4346f99e431c870e392a438684c0fe8", d};
  return t;
}

const MessageType& gnssGloEphemType() {
  static const std::string d = withDeps(
      "uint32 sat\nGnssTimeMsg ttr\nGnssTimeMsg toe\nint32  freqo\nuint32 iode\nuint32 health\nuint32 age\n"
      "float64 ura\nfloat64 pos_x\nfloat64 pos_y\nfloat64 pos_z\nfloat64 vel_x\nfloat64 vel_y\nfloat64 vel_z\n"
      "float64 acc_x\nfloat64 acc_y\nfloat64 acc_z\nfloat64 tau_n\nfloat64 gamma\nfloat64 delta_tau_n\n",
      {{"gnss_comm/GnssTimeMsg", kGnssTimeDef}});
  static const MessageType t{"gnss_comm/GnssGloEphemMsg", "6893dee0d8b1c9325a6693f3488e0144", d};
  return t;
}

// ---- serialise -------------------------------------------------------------------------------

std::vector<std::uint8_t> serialize(const ImuMsg& m) {
  Writer w;
  w.header(m.header);
  w.fixed(m.orientation);
  w.fixed(m.orientationCovariance);
  w.fixed(m.angularVelocity);
  w.fixed(m.angularVelocityCovariance);
  w.fixed(m.linearAcceleration);
  w.fixed(m.linearAccelerationCovariance);
  return w.take();
}

std::vector<std::uint8_t> serialize(const ImageMsg& m) {
  Writer w;
  w.header(m.header);
  w.pod(m.height);
  w.pod(m.width);
  w.str(m.encoding);
  w.pod(m.isBigEndian);
  w.pod(m.step);
  w.vec(m.data);
  return w.take();
}

std::vector<std::uint8_t> serialize(const CompressedImageMsg& m) {
  Writer w;
  w.header(m.header);
  w.str(m.format);
  w.vec(m.data);
  return w.take();
}

std::vector<std::uint8_t> serialize(const GnssMeasMsg& m) {
  Writer w;
  w.count(m.meas.size());
  for (const GnssObsMsg& o : m.meas) {
    w.gnssTime(o.time);
    w.pod(o.sat);
    w.vec(o.freqs);
    w.vec(o.cn0);
    w.vec(o.lli);
    w.vec(o.code);
    w.vec(o.psr);
    w.vec(o.psrStd);
    w.vec(o.cp);
    w.vec(o.cpStd);
    w.vec(o.dopp);
    w.vec(o.doppStd);
    w.vec(o.status);
  }
  return w.take();
}

std::vector<std::uint8_t> serialize(const GnssEphemMsg& m) {
  Writer w;
  w.pod(m.sat);
  w.gnssTime(m.ttr);
  w.gnssTime(m.toe);
  w.gnssTime(m.toc);
  w.pod(m.toeTow);
  for (std::uint32_t v : {m.week, m.iode, m.iodc, m.health, m.code}) w.pod(v);
  for (double v : {m.ura, m.a, m.e, m.i0, m.omg, m.omg0, m.m0, m.deltaN, m.omgDot, m.iDot, m.cuc, m.cus, m.crc,
                   m.crs, m.cic, m.cis, m.af0, m.af1, m.af2, m.tgd0, m.tgd1, m.aDot, m.nDot})
    w.pod(v);
  return w.take();
}

std::vector<std::uint8_t> serialize(const GnssGloEphemMsg& m) {
  Writer w;
  w.pod(m.sat);
  w.gnssTime(m.ttr);
  w.gnssTime(m.toe);
  w.pod(m.freqo);
  w.pod(m.iode);
  w.pod(m.health);
  w.pod(m.age);
  w.pod(m.ura);
  w.fixed(m.pos);
  w.fixed(m.vel);
  w.fixed(m.acc);
  w.pod(m.tauN);
  w.pod(m.gamma);
  w.pod(m.deltaTauN);
  return w.take();
}

// ---- deserialise -----------------------------------------------------------------------------

ImuMsg deserializeImu(std::span<const std::uint8_t> bytes, std::string_view source, std::uint64_t baseOffset) {
  Reader r(bytes, source, baseOffset);
  ImuMsg m;
  m.header = r.header();
  r.fixed(m.orientation, "orientation");
  r.fixed(m.orientationCovariance, "orientation_covariance");
  r.fixed(m.angularVelocity, "angular_velocity");
  r.fixed(m.angularVelocityCovariance, "angular_velocity_covariance");
  r.fixed(m.linearAcceleration, "linear_acceleration");
  r.fixed(m.linearAccelerationCovariance, "linear_acceleration_covariance");
  r.end();
  return m;
}

ImageMsg deserializeImage(std::span<const std::uint8_t> bytes, std::string_view source, std::uint64_t baseOffset) {
  Reader r(bytes, source, baseOffset);
  ImageMsg m;
  m.header = r.header();
  m.height = r.pod<std::uint32_t>("height");
  m.width = r.pod<std::uint32_t>("width");
  m.encoding = r.str("encoding");
  m.isBigEndian = r.pod<std::uint8_t>("is_bigendian");
  m.step = r.pod<std::uint32_t>("step");
  m.data = r.vec<std::uint8_t>("data");
  r.end();
  return m;
}

CompressedImageMsg deserializeCompressedImage(std::span<const std::uint8_t> bytes, std::string_view source,
                                              std::uint64_t baseOffset) {
  Reader r(bytes, source, baseOffset);
  CompressedImageMsg m;
  m.header = r.header();
  m.format = r.str("format");
  m.data = r.vec<std::uint8_t>("data");
  r.end();
  return m;
}

GnssMeasMsg deserializeGnssMeas(std::span<const std::uint8_t> bytes, std::string_view source, std::uint64_t baseOffset) {
  Reader r(bytes, source, baseOffset);
  GnssMeasMsg m;
  // The smallest GnssObsMsg is 16 bytes of fixed fields and 11 empty arrays (44 bytes).
  const std::size_t n = r.count("meas", 16 + 11 * 4);
  m.meas.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::string f = "meas[" + std::to_string(i) + "]";
    GnssObsMsg& o = m.meas[i];
    o.time = r.gnssTime(f + ".time");
    o.sat = r.pod<std::uint32_t>(f + ".sat");
    o.freqs = r.vec<double>(f + ".freqs");
    o.cn0 = r.vec<double>(f + ".CN0");
    o.lli = r.vec<std::uint8_t>(f + ".LLI");
    o.code = r.vec<std::uint8_t>(f + ".code");
    o.psr = r.vec<double>(f + ".psr");
    o.psrStd = r.vec<double>(f + ".psr_std");
    o.cp = r.vec<double>(f + ".cp");
    o.cpStd = r.vec<double>(f + ".cp_std");
    o.dopp = r.vec<double>(f + ".dopp");
    o.doppStd = r.vec<double>(f + ".dopp_std");
    o.status = r.vec<std::uint8_t>(f + ".status");
  }
  r.end();
  return m;
}

GnssEphemMsg deserializeGnssEphem(std::span<const std::uint8_t> bytes, std::string_view source,
                                  std::uint64_t baseOffset) {
  Reader r(bytes, source, baseOffset);
  GnssEphemMsg m;
  m.sat = r.pod<std::uint32_t>("sat");
  m.ttr = r.gnssTime("ttr");
  m.toe = r.gnssTime("toe");
  m.toc = r.gnssTime("toc");
  m.toeTow = r.pod<double>("toe_tow");
  m.week = r.pod<std::uint32_t>("week");
  m.iode = r.pod<std::uint32_t>("iode");
  m.iodc = r.pod<std::uint32_t>("iodc");
  m.health = r.pod<std::uint32_t>("health");
  m.code = r.pod<std::uint32_t>("code");
  const std::pair<double*, const char*> fields[] = {
      {&m.ura, "ura"},       {&m.a, "A"},         {&m.e, "e"},         {&m.i0, "i0"},
      {&m.omg, "omg"},       {&m.omg0, "OMG0"},   {&m.m0, "M0"},       {&m.deltaN, "delta_n"},
      {&m.omgDot, "OMG_dot"}, {&m.iDot, "i_dot"}, {&m.cuc, "cuc"},     {&m.cus, "cus"},
      {&m.crc, "crc"},       {&m.crs, "crs"},     {&m.cic, "cic"},     {&m.cis, "cis"},
      {&m.af0, "af0"},       {&m.af1, "af1"},     {&m.af2, "af2"},     {&m.tgd0, "tgd0"},
      {&m.tgd1, "tgd1"},     {&m.aDot, "A_dot"},  {&m.nDot, "n_dot"}};
  for (const auto& [p, name] : fields) *p = r.pod<double>(name);
  r.end();
  return m;
}

GnssGloEphemMsg deserializeGnssGloEphem(std::span<const std::uint8_t> bytes, std::string_view source,
                                        std::uint64_t baseOffset) {
  Reader r(bytes, source, baseOffset);
  GnssGloEphemMsg m;
  m.sat = r.pod<std::uint32_t>("sat");
  m.ttr = r.gnssTime("ttr");
  m.toe = r.gnssTime("toe");
  m.freqo = r.pod<std::int32_t>("freqo");
  m.iode = r.pod<std::uint32_t>("iode");
  m.health = r.pod<std::uint32_t>("health");
  m.age = r.pod<std::uint32_t>("age");
  m.ura = r.pod<double>("ura");
  r.fixed(m.pos, "pos");
  r.fixed(m.vel, "vel");
  r.fixed(m.acc, "acc");
  m.tauN = r.pod<double>("tau_n");
  m.gamma = r.pod<double>("gamma");
  m.deltaTauN = r.pod<double>("delta_tau_n");
  r.end();
  return m;
}

}  // namespace gvins::fusion::ros
