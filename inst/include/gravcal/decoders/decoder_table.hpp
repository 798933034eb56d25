// gravcal: the table of the formats the core decodes, and how each
// decoder is put together: its reader, and over it GGIR's resampling or
// time-gap filling where GGIR's reading has them (R/formats.R's registry
// names the decoders; a new format adds its row to find_decoder()).
//
// What the core cannot do itself comes from the host (DecoderHost): zlib's
// inflation for .gt3x, and whether R sums in long double. The host opens
// the bytes (a file, or gzip-compressed csv); a Movisens decoder reads its
// recording's unisens.xml and temp.bin itself, beside its acc.bin.
//
// Header-only, standard headers only.
#ifndef GRAVCAL_DECODER_TABLE_HPP
#define GRAVCAL_DECODER_TABLE_HPP

#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"
#include "gravcal/decoders/decode_csv.hpp"
#include "gravcal/decoders/decode_cwa.hpp"
#include "gravcal/decoders/decode_geneactiv.hpp"
#include "gravcal/decoders/decode_ggir_resample.hpp"
#include "gravcal/decoders/decode_ggir_timegaps.hpp"
#include "gravcal/decoders/decode_gt3x.hpp"
#include "gravcal/decoders/decode_movisens.hpp"
#include "gravcal/decoders/decode_parmay.hpp"

namespace gravcal {

using DecoderPtr = std::unique_ptr<Decoder>;

// What the decoders need from their host that the header-only core does
// not have: zlib's inflation of a .gt3x file's deflated entries, and
// whether the host's R sums in long double (GGIR's time-gap filling
// normalises a repeated sample with R's sums).
struct DecoderHost {
  EntryInflater* inflater = nullptr;
  bool long_double = true;
};

// One native decoder: its name, whether its bytes may come gzip-compressed,
// and how to make it on a file's bytes (`name` tells the csv decoder which
// layout to expect).
struct DecoderKind {
  const char* name;
  bool gzip;
  DecoderPtr (*make)(ByteSource& bytes, const Options& opts, const std::string& name,
                     const DecoderHost& host);
};

inline DecoderPtr make_cwa(ByteSource& bytes, const Options& opts,
                           const std::string&, const DecoderHost&) {
  return DecoderPtr(new CwaDecoder(bytes, opts));
}

inline DecoderPtr make_csv(ByteSource& bytes, const Options& opts,
                           const std::string& name, const DecoderHost&) {
  return DecoderPtr(new CsvDecoder(bytes, opts, name));
}

inline DecoderPtr make_geneactiv(ByteSource& bytes, const Options& opts,
                                 const std::string&, const DecoderHost&) {
  std::unique_ptr<GeneactivDecoder> d(new GeneactivDecoder(bytes, opts));
  // GGIR resamples a rate that is not whole onto whole Hz (compat = 1;
  // resample = 0 gives GGIRread::readGENEActiv's samples as they are)
  const ReadRules r = ReadRules::of(opts);
  if (!r.compat || opts.num("resample", 1) == 0) return d;
  return DecoderPtr(new GgirResampler(std::move(d), 0, r.interpolation, false, r.fused));
}

// An Axivity csv export: the csv decoder with the layout in the options;
// GGIR resamples it block by block onto the rate found from its time
// stamps (option grid_sf; compat = 1), gravcal's own reads keep it as it is.
inline DecoderPtr make_axivity_csv(ByteSource& bytes, const Options& opts,
                                   const std::string& name, const DecoderHost&) {
  std::unique_ptr<CsvDecoder> d(new CsvDecoder(bytes, opts, name));
  const ReadRules r = ReadRules::of(opts);
  if (!r.compat) return d;
  // (a NaN time stamp, force_tz()'s in an hour the zone's clocks skip, read
  // as GGIRread::resample() reads it)
  return DecoderPtr(new GgirResamplerOf<CsvDecoder>(
      std::move(d), opts.num("grid_sf", opts.num("sf", 0)), r.interpolation, false, r.fused,
      true));
}

// GGIR's ad hoc csv: the csv decoder with the rmc.* layout; with
// rmc.check4timegaps and a time column (option timegaps > 0: the rate),
// each block's time gaps filled as g.imputeTimegaps fills them; with
// rmc.doresample and a UNIX time column (option grid_sf > 0; compat = 1),
// resampled block by block onto that rate, the grid's last point kept
// (after the gaps are filled, as read.myacc.csv does).
template <class Inner>
DecoderPtr adhoc_resampled(std::unique_ptr<Inner> d, const Options& opts) {
  const double grid = opts.num("grid_sf", 0);
  const ReadRules r = ReadRules::of(opts);
  if (!r.compat || !(grid > 0)) return DecoderPtr(d.release());
  return DecoderPtr(new GgirResamplerOf<Inner>(std::move(d), grid, r.interpolation, true,
                                                        r.fused));
}

// With timegaps_carry = 1 (g.getmeta()'s reading), each block's filling
// starts from the previous block's last sample and time, as read.myacc.csv's
// does when g.readaccfile() hands it GGIR's PreviousLastValue and
// PreviousLastTime; its counters are named "rmc_..." (g.getmeta()'s own
// filling, over it, counts GGIR's QClog).
inline DecoderPtr make_adhoc_csv(ByteSource& bytes, const Options& opts,
                                 const std::string& name, const DecoderHost& host) {
  std::unique_ptr<CsvDecoder> d(new CsvDecoder(bytes, opts, name));
  const double gaps = opts.num("timegaps", 0);
  if (!(gaps > 0)) return adhoc_resampled(std::move(d), opts);
  GgirTimegapsMode m;
  if (opts.num("timegaps_carry", 0) != 0) {
    m.carry = true;
    m.counter_prefix = "rmc_";
  }
  if (host.long_double) {
    using Gaps = GgirTimegapsOf<CsvDecoder, long double>;
    return adhoc_resampled(std::unique_ptr<Gaps>(new Gaps(std::move(d), gaps, m)), opts);
  }
  using Gaps = GgirTimegapsOf<CsvDecoder, double>;
  return adhoc_resampled(std::unique_ptr<Gaps>(new Gaps(std::move(d), gaps, m)), opts);
}

// .gt3x: the decoder reads the zip's entries itself, the host's inflater
// inflating the deflated ones
inline DecoderPtr make_gt3x(ByteSource& bytes, const Options& opts,
                            const std::string&, const DecoderHost& host) {
  return DecoderPtr(new Gt3xDecoder(bytes, opts, host.inflater));
}

// A Parmay Matrix .bin: resampled onto its grid as GGIRread does (option
// interpolation: GGIR's interpolationType; compat = 0 skips damaged packets)
inline DecoderPtr make_parmay(ByteSource& bytes, const Options& opts,
                              const std::string&, const DecoderHost&) {
  return DecoderPtr(new ParmayDecoder(bytes, opts));
}

// A Movisens recording: `bytes` are its acc.bin; unisens.xml and temp.bin
// come from the same folder (the folder of option file_path). The xml is read whole, up
// to 16 MB (a real one is a few kB); temp.bin may be absent.
inline DecoderPtr make_movisens(ByteSource& bytes, const Options& opts,
                                const std::string&, const DecoderHost&) {
  const std::string path = opts.str("file_path", "acc.bin");
  const std::size_t slash = path.find_last_of("/\\");
  const std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
  std::string xml;
  FileSource xf((dir + "/unisens.xml").c_str());
  if (xf.is_open()) {
    const std::size_t cap = 16u << 20;
    unsigned char buf[65536];
    std::size_t got = 0;
    while ((got = xf.read(buf, sizeof buf)) > 0 && xml.size() < cap) {
      xml.append(reinterpret_cast<const char*>(buf), got);
    }
    if (xml.size() >= cap) xml = "<toolong";
  }
  std::unique_ptr<FileSource> temp(new FileSource((dir + "/temp.bin").c_str()));
  std::unique_ptr<ByteSource> t;
  if (temp->is_open()) t = std::move(temp);
  return DecoderPtr(new MovisensDecoder(bytes, opts, xml, std::move(t)));
}

// The table's row for `format`, or null when there is none.
inline const DecoderKind* find_decoder(const std::string& format) {
  static const DecoderKind kinds[] = {
      {"actigraph_csv", true, make_csv},
      {"csv", true, make_csv},
      {"adhoc_csv", true, make_adhoc_csv},
      {"axivity_csv", true, make_axivity_csv},
      {"gt3x", false, make_gt3x},
      {"cwa", false, make_cwa},
      {"geneactiv", false, make_geneactiv},
      {"parmay", false, make_parmay},
      {"movisens", false, make_movisens},
  };
  for (const DecoderKind& k : kinds) {
    if (format == k.name) return &k;
  }
  return nullptr;
}

// Numbers in text, "a b a b ..." ("NaN" for NaN), as pairs.
inline std::vector<double> number_pairs(const std::string& text, const char* what) {
  std::vector<double> out;
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t used = 0;
    const std::string rest = text.substr(at);
    double v = 0;
    if (rest.compare(0, 3, "NaN") == 0) {
      v = std::numeric_limits<double>::quiet_NaN();
      used = 3;
    } else {
      v = std::stod(rest, &used);
    }
    out.push_back(v);
    at += used;
    while (at < text.size() && text[at] == ' ') ++at;
  }
  if (out.size() % 2 != 0) throw std::invalid_argument(std::string(what) + ": pairs of numbers");
  return out;
}

// g.getmeta()'s time-gap imputation over a decoder (option getmeta_timegaps
// = 1; GgirTimegapsOf's carry mode): getmeta_gap_limit (minutes), and
// clock, GGIR's reader's clock shifts as text "second shift second shift
// ..." (shift NaN: the clock time does not exist), up to clock_until; with
// getmeta_epoch_gaps = 1 the gaps over the limit imputed at epoch level
// (short_epoch, long_epoch seconds; local_zone: "second offset ..." of the
// zone their times of day are read in).
inline DecoderPtr getmeta_timegaps(DecoderPtr d, const Options& opts, const DecoderHost& host) {
  GgirTimegapsMode m;
  m.carry = true;
  m.limit_minutes = opts.num("getmeta_gap_limit", 0);
  m.clock = number_pairs(opts.str("clock", ""), "clock");
  m.epoch_gaps = opts.num("getmeta_epoch_gaps", 0) != 0;
  m.short_epoch = opts.num("short_epoch", 5);
  m.long_epoch = opts.num("long_epoch", 900);
  m.local = number_pairs(opts.str("local_zone", ""), "local_zone");
  m.clock_until = opts.num("clock_until", std::numeric_limits<double>::infinity());
  if (host.long_double) {
    using Gaps = GgirTimegapsOf<Decoder, long double>;
    return DecoderPtr(new Gaps(std::move(d), 0, std::move(m)));
  }
  using Gaps = GgirTimegapsOf<Decoder, double>;
  return DecoderPtr(new Gaps(std::move(d), 0, std::move(m)));
}

// The decoder for `format` on `bytes`, or null when there is none.
inline DecoderPtr make_decoder(const std::string& format, ByteSource& bytes,
                               const Options& opts, const DecoderHost& host) {
  const DecoderKind* kind = find_decoder(format);
  if (kind == nullptr) return nullptr;
  DecoderPtr d = kind->make(bytes, opts, format, host);
  if (d && opts.num("getmeta_timegaps", 0) != 0) return getmeta_timegaps(std::move(d), opts, host);
  return d;
}

}  // namespace gravcal

#endif  // GRAVCAL_DECODER_TABLE_HPP
