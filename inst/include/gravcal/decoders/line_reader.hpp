// gravcal: lines of text from a byte stream through one fixed buffer (the
// csv decoder's and the GENEActiv decoder's reader).
#ifndef GRAVCAL_LINE_READER_HPP
#define GRAVCAL_LINE_READER_HPP

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "gravcal/decoders/decode.hpp"

namespace gravcal {

// One line of the input (without its line end), where it was, and how it
// ended.
struct Line {
  const char* p = nullptr;
  std::size_t n = 0;
  std::int64_t number = 0;   // 1-based line number in the file
  std::int64_t offset = 0;   // byte offset of its first byte
  bool has_end = true;       // ended by '\n' (else: the input ended)
  bool too_long = false;     // longer than the limit; p, n hold its start
  bool cr = false;           // a '\r' at its end was dropped (it is still at p[n])
};

// Lines from a ByteSource through one fixed buffer. A line ends at '\n'
// (one '\r' before it is dropped: CRLF); the last line may end with the
// input instead (has_end false: a cut last line is given as it is, '\r'
// dropped too). A line longer than the limit is given as too_long (its
// first bytes, has_end true) and the rest of it, up to and with its '\n',
// is skipped, so memory stays at the buffer. Whether a line over the limit
// is cut depends on where it lies in the buffer: it is cut only when the
// limit's worth of it is buffered without its '\n' (a longer line whose
// '\n' is already buffered is given whole). The buffer is refilled with as
// many bytes as fit (read_full(): every ByteSource returns fewer only at
// the end of its input or on a failure); a short refill is the end.
class LineReader {
 public:
  static constexpr std::size_t kBuffer = std::size_t(1) << 20;
  static constexpr std::size_t kMaxLine = 65536;
  static constexpr std::size_t kMinBuffer = 64;
  // bytes readable after the buffered ones (a word read at the last byte)
  static constexpr std::size_t kPad = 8;
  // `buffer` bytes (tests and fuzzers use small ones to cross refills
  // often); lines longer than `max_line` bytes, or than half of a smaller
  // buffer, count as overlong. The csv decoder: 1 MiB and 65536; the
  // GENEActiv decoder: 64 KiB and 8192.
  explicit LineReader(ByteSource& src, std::size_t buffer = kBuffer,
                      std::size_t max_line = kMaxLine)
      : src_(src), cap_(std::max(kMinBuffer, std::min(buffer, kBuffer))), buf_(cap_ + kPad),
        max_line_(std::min(max_line, cap_ / 2)) {}

  // The next line into `ln`; false at the end of the input (`ln` is then
  // left as it was: the last line given).
  bool next(Line& ln) {
    if (again_) {
      again_ = false;
      ln = last_;
      return true;
    }
    if (!next_line(ln)) return false;
    last_ = ln;
    return true;
  }
  // next() gives the line it gave last once more (its bytes are still
  // where they were: nothing is read in between).
  void unread() { again_ = true; }
  // After next() gave a line too_long: skips the rest of it now rather
  // than with the next line, and says how it ended: true at its '\n',
  // false when the input ended inside it (then next() gives nothing more).
  // The line's bytes (p, n) may move: read them first.
  bool finish_overlong() {
    while (skipping_) {
      const char* b = buf_.data() + beg_;
      const void* nl = std::memchr(b, '\n', end_ - beg_);
      if (nl != nullptr) {
        skipping_ = false;
        advance(static_cast<std::size_t>(static_cast<const char*>(nl) - b) + 1, false);
        return true;
      }
      advance(end_ - beg_, false);
      if (!fill()) return false;
    }
    return true;
  }
  // No more lines (the input ended and every byte was given).
  bool exhausted() {
    for (;;) {
      if (skipping_ && beg_ < end_) {
        const void* nl = std::memchr(buf_.data() + beg_, '\n', end_ - beg_);
        if (nl != nullptr) return false;  // the overlong line ends: more follows
        advance(end_ - beg_, false);      // still inside it: drop what is read
      }
      if (beg_ < end_) return false;
      if (!fill()) return true;
    }
  }
  // The unread bytes buffered up to and with the last '\n': whole lines, to
  // be parsed where they lie (none while inside an overlong line), with
  // kPad readable bytes after them. What next() gives of them is these
  // lines one by one.
  std::size_t whole_lines(const char*& p) const {
    p = buf_.data() + beg_;
    return skipping_ || whole_end_ <= beg_ ? 0 : whole_end_ - beg_;
  }
  // Moves past `bytes` bytes of whole_lines(), the first `lines` lines.
  void consume(std::size_t bytes, std::int64_t lines) {
    beg_ += bytes;
    offset_ += static_cast<std::int64_t>(bytes);
    line_ += lines;
  }
  // The bytes buffered ahead (for looking at the first data lines).
  void peek(const char*& p, std::size_t& n) {
    if (!eof_ && end_ - beg_ < cap_ / 2) fill();
    p = buf_.data() + beg_;
    n = end_ - beg_;
  }
  // The bytes buffered ahead, after reading until at least `want` of them
  // (at most the buffer's) are there or the input ends.
  std::size_t peek_at_least(const char*& p, std::size_t want) {
    want = std::min(want, cap_);
    while (end_ - beg_ < want && fill()) {
    }
    p = buf_.data() + beg_;
    return end_ - beg_;
  }
  // Skips k lines as data.table::fread's `skip` counts them: a line ends at
  // '\n', at '\r' and at the pairs "\r\n" and "\n\r" (next() ends lines at
  // '\n' only). Returns the lines skipped (fewer at the end of the input).
  std::int64_t skip_fread_lines(std::int64_t k) {
    std::int64_t done = 0;
    while (done < k) {
      const char* p;
      std::size_t n;
      peek(p, n);
      if (n == 0) break;
      std::size_t i = 0;
      for (; i < n && done < k; ++i) {
        const char c = p[i];
        if (c != '\n' && c != '\r') continue;
        const char other = c == '\n' ? '\r' : '\n';
        if (i + 1 == n && !eof_ && i > 0) break;  // its pair may follow: read on first
        if (i + 1 < n && p[i + 1] == other) ++i;
        ++done;
      }
      consume(i, 0);
    }
    line_ += done;
    return done;
  }

  // Starts again at byte `pos` of the source (whose line number is `line`).
  bool rewind(std::int64_t pos, std::int64_t line) {
    if (!src_.seek(pos)) return false;
    beg_ = end_ = whole_end_ = 0;
    eof_ = skipping_ = again_ = false;
    offset_ = pos;
    line_ = line;
    return true;
  }
  std::int64_t offset() const { return offset_; }
  std::int64_t line_number() const { return line_; }
  bool read_failed() const { return src_.failed(); }
  bool input_ended() const { return eof_; }

 private:
  bool next_line(Line& ln) {
    for (;;) {
      const char* b = buf_.data() + beg_;
      const void* nl = std::memchr(b, '\n', end_ - beg_);
      if (nl != nullptr) {
        const std::size_t len = static_cast<std::size_t>(static_cast<const char*>(nl) - b);
        if (skipping_) { skipping_ = false; advance(len + 1, false); continue; }
        return give(ln, len, true);
      }
      if (skipping_) { advance(end_ - beg_, false); if (!fill()) return false; continue; }
      if (end_ - beg_ >= max_line_) {
        ln = make(max_line_, true);
        ln.too_long = true;
        skipping_ = true;
        advance(max_line_, true);
        return true;
      }
      if (!fill()) {
        if (beg_ == end_) return false;
        return give(ln, end_ - beg_, false);
      }
    }
  }
  Line make(std::size_t len, bool has_end) {
    Line ln;
    ln.p = buf_.data() + beg_;
    ln.n = len;
    ln.number = line_ + 1;
    ln.offset = offset_;
    ln.has_end = has_end;
    if (ln.n > 0 && ln.p[ln.n - 1] == '\r') {  // CRLF
      --ln.n;
      ln.cr = true;
    }
    return ln;
  }
  bool give(Line& ln, std::size_t len, bool has_end) {
    ln = make(len, has_end);
    advance(len + (has_end ? 1 : 0), true);
    return true;
  }
  void advance(std::size_t k, bool new_line) {
    beg_ += k;
    offset_ += static_cast<std::int64_t>(k);
    if (new_line) ++line_;
  }
  // Moves the unread bytes to the front and reads more; false when nothing
  // more came (end of input, or a read error).
  bool fill() {
    if (eof_) return false;
    if (beg_ > 0) {
      std::memmove(buf_.data(), buf_.data() + beg_, end_ - beg_);
      end_ -= beg_;
      whole_end_ = whole_end_ > beg_ ? whole_end_ - beg_ : 0;
      beg_ = 0;
    }
    if (end_ == cap_) return true;
    const std::size_t got = read_full(src_, reinterpret_cast<unsigned char*>(buf_.data() + end_),
                                      cap_ - end_);
    for (std::size_t i = end_ + got; i > end_; --i) {
      if (buf_[i - 1] == '\n') { whole_end_ = i; break; }
    }
    end_ += got;
    if (end_ < cap_) eof_ = true;
    return got > 0;
  }

  ByteSource& src_;
  std::size_t cap_;        // bytes the buffer holds
  std::vector<char> buf_;  // cap_ bytes and kPad more, never read into
  std::size_t max_line_;
  std::size_t beg_ = 0, end_ = 0;
  std::size_t whole_end_ = 0;  // one past the last '\n' in buf_[0, end_), else 0
  std::int64_t offset_ = 0;    // source offset of buf_[beg_]
  std::int64_t line_ = 0;    // lines given so far
  bool eof_ = false;
  bool skipping_ = false;  // inside an overlong line
  bool again_ = false;     // unread(): next() gives last_ again
  Line last_;
};

}  // namespace gravcal

#endif  // GRAVCAL_LINE_READER_HPP
