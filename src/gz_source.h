// A ByteSource that gunzips a file (zlib's gzread; a file that is not gzip
// is read as it is). For .csv.gz; the decoders stay free of zlib.
#ifndef GRAVCAL_GLUE_GZ_SOURCE_H
#define GRAVCAL_GLUE_GZ_SOURCE_H

#include <zlib.h>

#include <climits>
#include <cstdint>
#include <cstdio>
#include <limits>

#include "gravcal/decoders/decode.hpp"

namespace gravcal_glue {

class GzSource : public gravcal::ByteSource {
 public:
  explicit GzSource(const char* path) {
    f_ = gzopen(path, "rb");
    if (f_ != nullptr) gzbuffer(f_, 1u << 18);
  }
  ~GzSource() override {
    if (f_ != nullptr) gzclose(f_);
  }
  GzSource(const GzSource&) = delete;
  GzSource& operator=(const GzSource&) = delete;
  bool is_open() const { return f_ != nullptr; }
  std::size_t read(unsigned char* buf, std::size_t n) override {
    if (f_ == nullptr || failed_) return 0;
    std::size_t got = 0;
    while (got < n) {
      const std::size_t want = n - got < static_cast<std::size_t>(INT_MAX) ? n - got : INT_MAX;
      const int k = gzread(f_, buf + got, static_cast<unsigned>(want));
      if (k < 0) {
        failed_ = true;  // a corrupt stream or a read error
        break;
      }
      if (k == 0) {
        int err = Z_OK;
        gzerror(f_, &err);
        if (err != Z_OK && err != Z_STREAM_END) failed_ = true;
        break;
      }
      got += static_cast<std::size_t>(k);
    }
    pos_ += static_cast<std::int64_t>(got);
    return got;
  }
  bool failed() const override { return failed_; }
  std::int64_t position() const override { return pos_; }
  // gzseek on a read stream: forward by decoding, back by starting again.
  // zlib's offset is z_off_t (a long: 32 bits on Windows) unless it was
  // built with 64-bit offsets (Z_LARGE64: gzseek64); a position beyond
  // what that type holds is refused (false: this source cannot seek
  // there) rather than wrapped to another position.
  bool seek(std::int64_t pos) override {
    if (f_ == nullptr || pos < 0) return false;
#if defined(Z_LARGE64)
    using gz_off = z_off64_t;
#else
    using gz_off = z_off_t;
#endif
    if (static_cast<std::uint64_t>(pos) >
        static_cast<std::uint64_t>(std::numeric_limits<gz_off>::max())) return false;
    const gz_off to = static_cast<gz_off>(pos);
#if defined(Z_LARGE64)
    if (gzseek64(f_, to, SEEK_SET) != to) return false;
#else
    if (gzseek(f_, to, SEEK_SET) != to) return false;
#endif
    pos_ = pos;
    failed_ = false;
    return true;
  }

 private:
  gzFile f_ = nullptr;
  std::int64_t pos_ = 0;
  bool failed_ = false;
};

// True when the file starts with gzip's magic bytes 1f 8b.
inline bool is_gzip(const char* path) {
  std::FILE* f = std::fopen(path, "rb");
  if (f == nullptr) return false;
  unsigned char m[2] = {0, 0};
  const std::size_t n = std::fread(m, 1, 2, f);
  std::fclose(f);
  return n == 2 && m[0] == 0x1f && m[1] == 0x8b;
}

}  // namespace gravcal_glue

#endif
