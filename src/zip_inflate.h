// zlib behind the core's EntryInflater (decode_gt3x.hpp): a deflated zip
// entry inflated as a stream through fixed buffers (raw deflate, RFC 1951).
#ifndef GRAVCAL_GLUE_ZIP_INFLATE_H
#define GRAVCAL_GLUE_ZIP_INFLATE_H

#include <zlib.h>

#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "gravcal/decoders/decode_gt3x.hpp"
#include "gravcal/decoders/read_ahead.hpp"

namespace gravcal_glue {

class InflateSource : public gravcal::ByteSource {
 public:
  explicit InflateSource(gravcal::ByteSource& raw) : raw_(raw), in_(kInLen) {
    std::memset(&z_, 0, sizeof z_);
    ok_ = inflateInit2(&z_, -MAX_WBITS) == Z_OK;  // raw deflate: no zlib header
    failed_ = !ok_;
  }
  ~InflateSource() override {
    if (ok_) inflateEnd(&z_);
  }
  InflateSource(const InflateSource&) = delete;
  InflateSource& operator=(const InflateSource&) = delete;

  std::size_t read(unsigned char* buf, std::size_t n) override {
    if (!ok_ || ended_ || failed_ || n == 0) return 0;
    z_.next_out = buf;
    z_.avail_out = static_cast<uInt>(n > kMaxOut ? kMaxOut : n);
    const uInt want = z_.avail_out;
    while (z_.avail_out > 0) {
      if (z_.avail_in == 0) {
        const std::size_t k = raw_.read(in_.data(), in_.size());
        if (k == 0) {  // deflate stream cut before its end
          failed_ = true;
          break;
        }
        z_.next_in = in_.data();
        z_.avail_in = static_cast<uInt>(k);
      }
      const int r = inflate(&z_, Z_NO_FLUSH);
      if (r == Z_STREAM_END) {
        ended_ = true;
        break;
      }
      if (r != Z_OK && r != Z_BUF_ERROR) {
        failed_ = true;
        break;
      }
    }
    const std::size_t got = want - z_.avail_out;
    pos_ += static_cast<std::int64_t>(got);
    return got;
  }
  bool failed() const override { return failed_; }
  std::int64_t position() const override { return pos_; }

 private:
  static constexpr std::size_t kInLen = 1 << 16;
  static constexpr std::size_t kMaxOut = 1u << 30;
  gravcal::ByteSource& raw_;
  std::vector<unsigned char> in_;
  z_stream z_;
  bool ok_ = false, ended_ = false, failed_ = false;
  std::int64_t pos_ = 0;
};

// `ahead`: each entry inflated on a second thread, ahead of its reader
// (gravcal/decoders/read_ahead.hpp).
class ZlibInflater : public gravcal::EntryInflater {
 public:
  explicit ZlibInflater(bool ahead = false) : ahead_(ahead) {}
  std::unique_ptr<gravcal::ByteSource> open(gravcal::ByteSource& raw) override {
    std::unique_ptr<gravcal::ByteSource> z(new InflateSource(raw));
    if (!ahead_) return z;
    return std::unique_ptr<gravcal::ByteSource>(new gravcal::ReadAheadSource(std::move(z)));
  }

 private:
  bool ahead_;
};

}  // namespace gravcal_glue

#endif
