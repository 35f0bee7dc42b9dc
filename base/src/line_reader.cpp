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

void LineReader::tooLong() const {
  throw ParseError(name_, line_ + 1, "", "line longer than " + std::to_string(maxLen_) + " characters");
}

std::string_view LineReader::lastLine() const {
  switch (lastIn_) {
    case Storage::Memory: return mem_.substr(lastPos_, lastLen_);
    case Storage::Buffer: return std::string_view(buf_).substr(lastPos_, lastLen_);
    case Storage::Spill: return std::string_view(spill_).substr(lastPos_, lastLen_);
    case Storage::Saved: break;
  }
  return saved_;
}

void LineReader::saveLast(Storage overwritten) {
  // Once per buffer refill at most: the line stays available to unread().
  if (lastIn_ != overwritten) return;
  saved_.assign(lastLine());
  lastIn_ = Storage::Saved;
}

bool LineReader::next(std::string_view& line) {
  if (pushedBack_) {
    pushedBack_ = false;
    line = lastLine();
    ++line_;
    return true;
  }
  if (!gz_) {
    if (memPos_ >= mem_.size()) return false;
    const std::size_t nl = mem_.find('\n', memPos_);
    const std::size_t end = nl == std::string_view::npos ? mem_.size() : nl;
    if (end - memPos_ > maxLen_) tooLong();
    lastIn_ = Storage::Memory;
    lastPos_ = memPos_;
    lastLen_ = end - memPos_;
    memPos_ = nl == std::string_view::npos ? mem_.size() : nl + 1;
  } else {
    if (bufPos_ >= buf_.size()) {
      saveLast(Storage::Buffer);
      if (!fill()) return false;
    }
    const char* start = buf_.data() + bufPos_;
    const std::size_t avail = buf_.size() - bufPos_;
    const void* nlp = std::memchr(start, '\n', avail);
    if (nlp) {
      // The common case: the whole line is in the buffer.
      const std::size_t take = static_cast<std::size_t>(static_cast<const char*>(nlp) - start);
      if (take > maxLen_) tooLong();
      lastIn_ = Storage::Buffer;
      lastPos_ = bufPos_;
      lastLen_ = take;
      bufPos_ += take + 1;
    } else {
      // The line continues after a refill: collect it in spill_.
      if (avail > maxLen_) tooLong();
      saveLast(Storage::Spill);
      saveLast(Storage::Buffer);
      spill_.assign(start, avail);
      bufPos_ = buf_.size();
      while (fill()) {
        const char* s = buf_.data();
        const void* p = std::memchr(s, '\n', buf_.size());
        const std::size_t take = p ? static_cast<std::size_t>(static_cast<const char*>(p) - s) : buf_.size();
        if (spill_.size() + take > maxLen_) tooLong();
        spill_.append(s, take);
        bufPos_ = take;
        if (p) {
          ++bufPos_;
          break;
        }
      }
      lastIn_ = Storage::Spill;
      lastPos_ = 0;
      lastLen_ = spill_.size();
    }
  }
  if (lastLen_ > 0 && lastLine().back() == '\r') --lastLen_;
  line = lastLine();
  ++line_;
  return true;
}

bool LineReader::next(std::string& line) {
  std::string_view v;
  if (!next(v)) {
    line.clear();
    return false;
  }
  line.assign(v);
  return true;
}

void LineReader::unread() {
  if (line_ > 0 && !pushedBack_) {
    pushedBack_ = true;
    --line_;
  }
}

}  // namespace gvins
