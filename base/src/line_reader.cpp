#include "gvins/base/line_reader.hpp"

#include <zlib.h>

#include <cstring>

namespace gvins {

struct LineReader::GzFile {
  gzFile f = nullptr;
  ~GzFile() {
    if (f) gzclose(f);
  }
};

LineReader::LineReader(const std::string& path, std::size_t maxLineLength)
    : gz_(std::make_unique<GzFile>()), name_(path), maxLen_(maxLineLength) {
  // gzopen reads uncompressed files transparently.
  gz_->f = gzopen(path.c_str(), "rb");
  if (!gz_->f) throw ParseError(path, 0, "", std::string("cannot open file: ") + std::strerror(errno));
  gzbuffer(gz_->f, 1 << 16);
}

LineReader::LineReader(std::string_view text, std::string name, std::size_t maxLineLength)
    : mem_(text), name_(std::move(name)), maxLen_(maxLineLength) {}

LineReader::~LineReader() = default;
LineReader::LineReader(LineReader&&) noexcept = default;
LineReader& LineReader::operator=(LineReader&&) noexcept = default;

bool LineReader::fill() {
  if (eof_) return false;
  if (!gz_) {
    eof_ = true;
    return false;
  }
  buf_.resize(1 << 16);
  const int n = gzread(gz_->f, buf_.data(), static_cast<unsigned>(buf_.size()));
  if (n < 0) {
    int err = 0;
    const char* msg = gzerror(gz_->f, &err);
    throw ParseError(name_, line_ + 1, "", std::string("read error: ") + (msg ? msg : "unknown"));
  }
  buf_.resize(static_cast<std::size_t>(n));
  bufPos_ = 0;
  if (n == 0) {
    eof_ = true;
    return false;
  }
  return true;
}

bool LineReader::next(std::string& line) {
  if (pushedBack_) {
    pushedBack_ = false;
    line = last_;
    ++line_;
    return true;
  }
  line.clear();
  bool any = false;
  if (!gz_) {
    if (memPos_ >= mem_.size()) return false;
    const std::size_t nl = mem_.find('\n', memPos_);
    const std::size_t end = nl == std::string_view::npos ? mem_.size() : nl;
    if (end - memPos_ > maxLen_) {
      throw ParseError(name_, line_ + 1, "", "line longer than " + std::to_string(maxLen_) + " characters");
    }
    line.assign(mem_.substr(memPos_, end - memPos_));
    memPos_ = nl == std::string_view::npos ? mem_.size() : nl + 1;
    any = true;
  } else {
    for (;;) {
      if (bufPos_ >= buf_.size() && !fill()) break;
      any = true;
      const char* start = buf_.data() + bufPos_;
      const std::size_t avail = buf_.size() - bufPos_;
      const void* nlp = std::memchr(start, '\n', avail);
      const std::size_t take = nlp ? static_cast<std::size_t>(static_cast<const char*>(nlp) - start) : avail;
      if (line.size() + take > maxLen_) {
        throw ParseError(name_, line_ + 1, "", "line longer than " + std::to_string(maxLen_) + " characters");
      }
      line.append(start, take);
      bufPos_ += take;
      if (nlp) {
        ++bufPos_;
        break;
      }
    }
    if (!any) return false;
  }
  if (!line.empty() && line.back() == '\r') line.pop_back();
  ++line_;
  last_ = line;
  return true;
}

void LineReader::unread() {
  if (line_ > 0 && !pushedBack_) {
    pushedBack_ = true;
    --line_;
  }
}

}  // namespace gvins
