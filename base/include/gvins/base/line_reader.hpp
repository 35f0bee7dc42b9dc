// Streaming line reader over a text file (plain or gzip-compressed, detected from the content)
// or an in-memory buffer, counting lines for error messages. Lines longer than a limit are an
// error rather than unbounded memory use.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>

#include "gvins/base/text_fields.hpp"

namespace gvins {

class LineReader {
 public:
  /// Opens a file; throws ParseError (line 0) if it cannot be opened.
  explicit LineReader(const std::string& path, std::size_t maxLineLength = 4096);
  /// Reads from memory (fuzzing, tests, network buffers); `name` is used in error messages.
  LineReader(std::string_view text, std::string name, std::size_t maxLineLength = 4096);
  ~LineReader();
  LineReader(LineReader&&) noexcept;
  LineReader& operator=(LineReader&&) noexcept;
  LineReader(const LineReader&) = delete;
  LineReader& operator=(const LineReader&) = delete;

  /// Reads the next line without its terminator ('\n', "\r\n"). Returns false at end of input.
  /// Throws ParseError for a line longer than the limit, or for a read error/corrupt gzip stream.
  bool next(std::string& line);
  /// The same without a copy: `line` views the reader's buffer and stays valid until the next
  /// call of next(), or until the reader is moved or destroyed.
  bool next(std::string_view& line);
  /// Pushes the last line back so that the next call to next() returns it again (one level).
  void unread();

  /// 1-based number of the line last returned (0 before the first).
  std::int64_t lineNumber() const { return line_; }
  const std::string& name() const { return name_; }
  TextLocation location() const { return {name_, line_}; }

 private:
  struct GzFile;
  std::unique_ptr<GzFile> gz_;
  std::string_view mem_;
  std::size_t memPos_ = 0;
  std::string name_;
  std::size_t maxLen_;
  std::int64_t line_ = 0;
  // The last line returned, for unread(): offset and length in its storage.
  enum class Storage { Memory, Buffer, Spill, Saved };
  Storage lastIn_ = Storage::Memory;
  std::size_t lastPos_ = 0, lastLen_ = 0;
  bool pushedBack_ = false;
  std::string buf_;         // the file's bytes; the first bufLen_ of them are valid
  std::size_t bufLen_ = 0;
  std::size_t bufPos_ = 0;
  std::string spill_;  // a line that continues across a buffer refill
  std::string saved_;  // the last line, when its storage is about to be overwritten
  bool eof_ = false;
  bool fill();
  std::string_view lastLine() const;
  void saveLast(Storage overwritten);
  [[noreturn]] void tooLong() const;
};

}  // namespace gvins
