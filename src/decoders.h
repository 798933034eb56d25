// The formats gravcal decodes natively, and what each needs from outside the
// header-only core (a zip entry's inflated bytes, for .gt3x). Each format
// adds its branch to the two functions below.
#ifndef GRAVCAL_GLUE_DECODERS_H
#define GRAVCAL_GLUE_DECODERS_H

#include <memory>
#include <string>

#include "gravcal/decode.hpp"
#include "gravcal/decode_csv.hpp"
#include "gravcal/decode_cwa.hpp"
#include "gravcal/decode_geneactiv.hpp"
#include "gravcal/decode_ggir_resample.hpp"
#include "gravcal/decode_gt3x.hpp"
#include "gz_source.h"
#include "zip_inflate.h"

namespace gravcal_glue {

// The bytes the decoder of `format` reads from `path` (the file itself, or
// for a container format the entry inside it). Null, with `why`, on failure.
inline std::unique_ptr<gravcal::ByteSource> open_bytes(const std::string& path,
                                                       const std::string& format,
                                                       const gravcal::Options& opts,
                                                       std::string& why) {
  (void)opts;
  if ((format == "csv" || format == "actigraph_csv") && is_gzip(path.c_str())) {
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

// The decoder for `format` on `bytes`, or null when there is none.
inline std::unique_ptr<gravcal::Decoder> make_decoder(const std::string& format,
                                                      gravcal::ByteSource& bytes,
                                                      const gravcal::Options& opts) {
  if (format == "cwa") {
    return std::unique_ptr<gravcal::Decoder>(new gravcal::CwaDecoder(bytes, opts));
  }
  if (format == "csv" || format == "actigraph_csv") {
    return std::unique_ptr<gravcal::Decoder>(new gravcal::CsvDecoder(bytes, opts, format));
  }
  if (format == "geneactiv") {
    std::unique_ptr<gravcal::GeneactivDecoder> d(new gravcal::GeneactivDecoder(bytes, opts));
    // GGIR resamples a rate that is not whole onto whole Hz (compat = 1;
    // resample = 0 gives GGIRread::readGENEActiv's samples as they are)
    if (opts.num("compat", 1) == 0 || opts.num("resample", 1) == 0) return d;
    return std::unique_ptr<gravcal::Decoder>(new gravcal::GgirResampler(std::move(d)));
  }
  // .gt3x: the decoder reads the zip's entries itself, zlib inflating
  if (format == "gt3x") {
    static gravcal_glue::ZlibInflater inflater;
    return std::unique_ptr<gravcal::Decoder>(new gravcal::Gt3xDecoder(bytes, opts, &inflater));
  }
  return nullptr;
}

}  // namespace gravcal_glue

#endif
