#include "gvins/rtcm/ntrip_response.hpp"

#include <algorithm>
#include <cctype>
#include <string_view>

#include "gvins/rtcm/ntrip_error.hpp"

namespace gvins::rtcm {
namespace {

using Kind = NtripError::Kind;

/// Printable rendering of untrusted text for error messages (at most 80 characters).
std::string printable(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 80)) {
    out.push_back(std::isprint(static_cast<unsigned char>(c)) ? c : '?');
  }
  if (s.size() > 80) out += "...";
  return out;
}

bool startsWithNoCase(std::string_view s, std::string_view prefix) {
  if (s.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[i])) != std::tolower(static_cast<unsigned char>(prefix[i]))) return false;
  }
  return true;
}

bool containsNoCase(std::string_view s, std::string_view needle) {
  for (std::size_t i = 0; i + needle.size() <= s.size(); ++i) {
    if (startsWithNoCase(s.substr(i), needle)) return true;
  }
  return false;
}

}  // namespace

bool NtripResponse::takeLine(std::string& line, std::size_t limit, const char* what) {
  const std::size_t nl = buf_.find('\n');
  if (nl == std::string::npos) {
    if (buf_.size() > limit) {
      throw NtripError(Kind::Protocol, std::string(what) + " longer than " + std::to_string(limit) + " bytes");
    }
    return false;
  }
  if (nl > limit) throw NtripError(Kind::Protocol, std::string(what) + " longer than " + std::to_string(limit) + " bytes");
  line.assign(buf_, 0, nl);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  buf_.erase(0, nl + 1);
  return true;
}

void NtripResponse::parseStatus(const std::string& line) {
  statusLine_ = printable(line);
  if (line.rfind("ICY 200", 0) == 0) {
    status_ = 200;
    state_ = State::IcyHeaders;
    return;
  }
  if (line.rfind("SOURCETABLE 200", 0) == 0) {
    status_ = 200;
    sourceTableType_ = true;
    state_ = State::Headers;
    return;
  }
  if (line.rfind("HTTP/1.", 0) == 0 && line.size() >= 12 && line[8] == ' ' &&
      std::isdigit(static_cast<unsigned char>(line[9])) && std::isdigit(static_cast<unsigned char>(line[10])) &&
      std::isdigit(static_cast<unsigned char>(line[11]))) {
    status_ = (line[9] - '0') * 100 + (line[10] - '0') * 10 + (line[11] - '0');
    state_ = State::Headers;
    return;
  }
  throw NtripError(Kind::Protocol, "caster answered '" + printable(line) + "', which is not an NTRIP response");
}

void NtripResponse::parseHeader(const std::string& line) {
  const std::size_t colon = line.find(':');
  if (colon == std::string::npos) throw NtripError(Kind::Protocol, "malformed header line '" + printable(line) + "'");
  const std::string_view name(line.data(), colon);
  const std::string_view value(line.data() + colon + 1, line.size() - colon - 1);
  if (startsWithNoCase(name, "transfer-encoding") && name.size() == 17 && containsNoCase(value, "chunked")) chunked_ = true;
  if (startsWithNoCase(name, "content-type") && name.size() == 12 && containsNoCase(value, "gnss/sourcetable")) sourceTableType_ = true;
}

void NtripResponse::finishHeaders() {
  const std::string mp = mount_.empty() ? std::string("(none)") : "'" + mount_ + "'";
  if (status_ == 401) {
    throw NtripError(Kind::Unauthorized, "caster refused the user name or password for mountpoint " + mp + " (" + statusLine_ + ")");
  }
  if (status_ == 404) {
    throw NtripError(Kind::MountpointNotFound, "mountpoint " + mp + " not found on the caster (" + statusLine_ + ")");
  }
  if (status_ != 200) throw NtripError(Kind::HttpStatus, "caster answered '" + statusLine_ + "' for mountpoint " + mp);
  if (sourceTableType_) {
    state_ = State::SourceTable;
    return;
  }
  state_ = chunked_ ? State::ChunkSize : State::Raw;
}

void NtripResponse::failSourceTable() {
  // Mountpoints are the second field of the table's STR records (NTRIP 2.0, source table).
  std::string names;
  int count = 0;
  std::size_t pos = 0;
  while ((pos = table_.find("STR;", pos)) != std::string::npos) {
    const std::size_t start = pos + 4;
    const std::size_t end = table_.find_first_of(";\r\n", start);
    if (end == std::string::npos) break;
    if (count < 20) names += (count ? ", " : "") + printable(table_.substr(start, end - start));
    ++count;
    pos = end;
  }
  if (count > 20) names += ", ...";
  const std::string mp = mount_.empty() ? std::string("(none)") : "'" + mount_ + "'";
  throw NtripError(Kind::MountpointNotFound,
                   "mountpoint " + mp + " not found: the caster sent its source table instead (" +
                       std::to_string(count) + " mountpoint" + (count == 1 ? "" : "s") +
                       (count ? ": " + names : std::string()) + ")");
}

void NtripResponse::feed(std::span<const std::uint8_t> bytes, std::vector<std::uint8_t>& payload) {
  if (state_ == State::Raw) {
    payload.insert(payload.end(), bytes.begin(), bytes.end());
    return;
  }
  if (state_ == State::Done) return;
  buf_.append(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  std::string line;
  for (;;) {
    switch (state_) {
      case State::Status:
      case State::Headers: {
        const std::size_t before = buf_.size();
        if (!takeLine(line, kMaxHeader, state_ == State::Status ? "status line" : "header line")) return;
        headerBytes_ += before - buf_.size();
        if (headerBytes_ > kMaxHeader) throw NtripError(Kind::Protocol, "response header longer than " + std::to_string(kMaxHeader) + " bytes");
        if (state_ == State::Status) parseStatus(line);
        else if (line.empty()) finishHeaders();
        else parseHeader(line);
        break;
      }
      case State::IcyHeaders: {
        // Optional header lines after "ICY 200 OK": printable "Name: value" lines up to an empty
        // line. The stream begins at the first byte that cannot start such a line.
        if (buf_.empty()) return;
        if (buf_[0] == '\r' || buf_[0] == '\n') {
          if (buf_[0] == '\r' && buf_.size() < 2) return;
          buf_.erase(0, buf_[0] == '\r' && buf_[1] == '\n' ? 2 : 1);
          state_ = State::Raw;
          break;
        }
        std::size_t i = 0;
        bool colon = false;
        while (i < buf_.size() && i < 1024 && std::isprint(static_cast<unsigned char>(buf_[i]))) {
          colon = colon || buf_[i] == ':';
          ++i;
        }
        if (i == buf_.size() && i < 1024) return;  // undecided yet
        if (i < buf_.size() && (buf_[i] == '\r' || buf_[i] == '\n') && colon && i > 0) {
          if (!takeLine(line, 1024, "header line")) return;
          headerBytes_ += line.size() + 2;
          if (headerBytes_ > kMaxHeader) throw NtripError(Kind::Protocol, "response header longer than " + std::to_string(kMaxHeader) + " bytes");
          break;
        }
        state_ = State::Raw;
        break;
      }
      case State::SourceTable: {
        // Search only the new bytes (and the end marker's length before them): a caster that
        // sends its table a byte at a time must not cost a scan of the whole table per byte.
        constexpr std::string_view kEnd = "ENDSOURCETABLE";
        const std::size_t from = table_.size() >= kEnd.size() ? table_.size() - (kEnd.size() - 1) : 0;
        table_ += buf_;
        buf_.clear();
        if (table_.find(kEnd, from) != std::string::npos || table_.size() > kMaxSourceTable) failSourceTable();
        return;
      }
      case State::Raw:
        payload.insert(payload.end(), buf_.begin(), buf_.end());
        buf_.clear();
        return;
      case State::ChunkSize: {
        if (!takeLine(line, 256, "chunk size line")) return;
        std::uint64_t n = 0;
        std::size_t digits = 0;
        for (char c : line) {
          if (c == ';' || c == ' ' || c == '\t') break;
          int v = -1;
          if (c >= '0' && c <= '9') v = c - '0';
          else if (c >= 'a' && c <= 'f') v = c - 'a' + 10;
          else if (c >= 'A' && c <= 'F') v = c - 'A' + 10;
          if (v < 0 || ++digits > 15) throw NtripError(Kind::Protocol, "bad chunk size line '" + printable(line) + "'");
          n = n * 16 + static_cast<std::uint64_t>(v);
        }
        if (digits == 0) throw NtripError(Kind::Protocol, "bad chunk size line '" + printable(line) + "'");
        chunkLeft_ = n;
        state_ = n == 0 ? State::Trailer : State::ChunkData;
        break;
      }
      case State::ChunkData: {
        const std::size_t take = static_cast<std::size_t>(std::min<std::uint64_t>(chunkLeft_, buf_.size()));
        payload.insert(payload.end(), buf_.begin(), buf_.begin() + static_cast<std::ptrdiff_t>(take));
        buf_.erase(0, take);
        chunkLeft_ -= take;
        if (chunkLeft_ > 0) return;
        state_ = State::ChunkEnd;
        break;
      }
      case State::ChunkEnd:
        if (!takeLine(line, 2, "chunk end")) return;
        if (!line.empty()) throw NtripError(Kind::Protocol, "chunk not followed by CR LF");
        state_ = State::ChunkSize;
        break;
      case State::Trailer:
        if (!takeLine(line, 1024, "trailer line")) return;
        if (line.empty()) {
          state_ = State::Done;
          buf_.clear();
          return;
        }
        break;
      case State::Done:
        buf_.clear();
        return;
    }
  }
}

void NtripResponse::end() {
  switch (state_) {
    case State::Status:
      throw NtripError(Kind::Connection, statusLine_.empty() && buf_.empty()
                                             ? "caster closed the connection without answering"
                                             : "caster closed the connection inside its status line");
    case State::Headers:
      // Some casters (RTKLIB's) send only the status line of an error and close.
      if (status_ != 200 && status_ != 0) finishHeaders();
      if (sourceTableType_) failSourceTable();
      throw NtripError(Kind::Connection, "caster closed the connection inside its response header");
    case State::SourceTable:
      failSourceTable();
    case State::ChunkData:
    case State::ChunkEnd:
      throw NtripError(Kind::Protocol, "stream ended inside a chunk");
    case State::ChunkSize:
      if (!buf_.empty()) throw NtripError(Kind::Protocol, "stream ended inside a chunk size line");
      return;
    default:
      return;
  }
}

}  // namespace gvins::rtcm
