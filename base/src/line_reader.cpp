#include "gvins/base/line_reader.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <cerrno>
#include <cstring>

namespace gvins {

namespace {
constexpr std::size_t kBufferSize = 1 << 16;
}

// A gzip stream read through zlib, or (f == nullptr) an uncompressed file read with read(2)
// straight into the line buffer: zlib's transparent mode would copy through its own input and
// output buffers (192 kB of fresh pages per file, one more copy of every byte).
struct LineReader::GzFile {
  gzFile f = nullptr;
  int fd = -1;
  ~GzFile() {
    if (f) gzclose(f);  // closes fd
    else if (fd >= 0) ::close(fd);
  }
};

LineReader::LineReader(const std::string& path, std::size_t maxLineLength)
    : gz_(std::make_unique<GzFile>()), name_(path), maxLen_(maxLineLength) {
  gz_->fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (gz_->fd < 0) throw ParseError(path, 0, "", std::string("cannot open file: ") + std::strerror(errno));
  struct stat st {};
  if (::fstat(gz_->fd, &st) == 0 && S_ISDIR(st.st_mode)) throw ParseError(path, 0, "", "is a directory, not a file");
  // Compression is detected from the content (the gzip magic bytes), as zlib does. A file that
  // cannot be peeked at (a pipe) is left to zlib, which reads either kind sequentially.
  unsigned char magic[2] = {0, 0};
  const ssize_t m = ::pread(gz_->fd, magic, 2, 0);
  if (m < 0 || (m == 2 && magic[0] == 0x1f && magic[1] == 0x8b)) {
    gz_->f = gzdopen(gz_->fd, "rb");
    if (!gz_->f) throw ParseError(path, 0, "", "cannot open file: out of memory");
    gzbuffer(gz_->f, 1 << 16);
  }
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
  if (buf_.size() != kBufferSize) buf_.resize(kBufferSize);  // once: later fills reuse it
  long n = 0;
  if (gz_->f) {
    n = gzread(gz_->f, buf_.data(), static_cast<unsigned>(buf_.size()));
    if (n < 0) {
      int err = 0;
      const char* msg = gzerror(gz_->f, &err);
      throw ParseError(name_, line_ + 1, "", std::string("read error: ") + (msg ? msg : "unknown"));
    }
    if (n == 0) {
      // zlib reports a stream that ends before its trailer (CRC-32 and length, RFC 1952 section
      // 2.3) as a non-fatal Z_BUF_ERROR: a cut-off file would otherwise read as complete.
      int err = 0;
      gzerror(gz_->f, &err);
      if (err == Z_BUF_ERROR)
        throw ParseError(name_, line_ + 1, "gzip stream",
                         "truncated gzip file: the compressed stream ends before its end (no CRC/length trailer)");
    }
  } else {
    // Fill the buffer as gzread does (short reads are continued) so that refills fall at the
    // same places.
    std::size_t got = 0;
    while (got < buf_.size()) {
      const ssize_t r = ::read(gz_->fd, buf_.data() + got, buf_.size() - got);
      if (r < 0) {
        if (errno == EINTR) continue;
        throw ParseError(name_, line_ + 1, "", std::string("read error: ") + std::strerror(errno));
      }
      if (r == 0) break;
      got += static_cast<std::size_t>(r);
    }
    n = static_cast<long>(got);
  }
  bufLen_ = static_cast<std::size_t>(n);
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
    if (bufPos_ >= bufLen_) {
      saveLast(Storage::Buffer);
      if (!fill()) return false;
    }
    const char* start = buf_.data() + bufPos_;
    const std::size_t avail = bufLen_ - bufPos_;
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
      bufPos_ = bufLen_;
      while (fill()) {
        const char* s = buf_.data();
        const void* p = std::memchr(s, '\n', bufLen_);
        const std::size_t take = p ? static_cast<std::size_t>(static_cast<const char*>(p) - s) : bufLen_;
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
