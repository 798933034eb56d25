// The decoders' host in the glue (gravcal/decoders/decoder_table.hpp has
// the formats' table and puts the decoders together): the bytes a decoder
// reads, a file or gzip-compressed csv; zlib's inflater for .gt3x; and R's
// answer to whether it sums in long double.
#ifndef GRAVCAL_GLUE_DECODERS_H
#define GRAVCAL_GLUE_DECODERS_H

#include <memory>
#include <string>

#include "gravcal/decoders/decoder_table.hpp"
#include "gz_source.h"
#include "r_services.h"
#include "zip_inflate.h"

namespace gravcal_glue {

using DecoderPtr = gravcal::DecoderPtr;

// The bytes the decoder of `format` reads from `path` (the file itself, or
// for a container format the entry inside it). Null, with `why`, on failure.
inline std::unique_ptr<gravcal::ByteSource> open_bytes(const std::string& path,
                                                       const std::string& format,
                                                       const gravcal::Options& opts,
                                                       std::string& why) {
  (void)opts;
  const gravcal::DecoderKind* kind = gravcal::find_decoder(format);
  if (kind != nullptr && kind->gzip && is_gzip(path.c_str())) {
    std::unique_ptr<GzSource> g(new GzSource(path.c_str()));
    if (!g->is_open()) {
      why = "cannot open the file";
      return nullptr;
    }
    return g;
  }
  std::unique_ptr<gravcal::FileSource> f(new gravcal::FileSource(path.c_str()));
  if (!f->is_open()) {
    why = "cannot open the file";
    return nullptr;
  }
  return f;
}

// The decoder for `format` on `bytes`, or null when there is none. With
// the option `threads` 2 or more, a deflated zip entry (.gt3x) is inflated
// on a second thread ahead of the decoder.
inline DecoderPtr make_decoder(const std::string& format, gravcal::ByteSource& bytes,
                               const gravcal::Options& opts) {
  static ZlibInflater inflater(false), ahead(true);
  gravcal::DecoderHost host;
  host.inflater = opts.num("threads", 1) >= 2 ? &ahead : &inflater;
  host.long_double = r_long_double();
  return gravcal::make_decoder(format, bytes, opts, host);
}

}  // namespace gravcal_glue

#endif
