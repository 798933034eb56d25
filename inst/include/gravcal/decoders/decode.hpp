// gravcal: what every device-file decoder shares.
//
// A decoder turns the bytes of a device file into samples in g (and degrees
// C, and seconds since 1970-01-01 UTC), pulled by the caller in chunks of a
// size the caller chooses, into arrays the caller owns. It reads its input
// sequentially through a ByteSource and keeps only fixed-size state (one
// format unit: a 512-byte block, a page, a line, a record), so memory does not
// grow with the recording. The caller decides how many samples it holds at
// once (a fixed buffer that feeds the segmenter, or a GGIR-sized block).
//
// Damage is never the end of the data. A decoder that meets a unit it cannot
// use (bad checksum, bad header, malformed line, impossible time stamp)
// skips it, counts it in its Report under a named counter, and goes on with
// the next good unit; only the true end of the input ends the data. A read
// error of the ByteSource is recorded (Report::read_error) and ends the data
// with the report saying so, never silently. Nothing read from a file sizes
// an allocation: counts and lengths from headers are checked against fixed
// limits of the format, and a jump in time is reported as a gap.
//
// Header-only, standard headers only (and the C library's 64-bit file
// positions: file_seek64()), no R. What needs a library (inflating
// a zip entry) is given to the decoder as a ByteSource from outside.
#ifndef GRAVCAL_DECODE_HPP
#define GRAVCAL_DECODE_HPP

#include "gravcal/mcu/fp_contract.hpp"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <stdio.h>  // _fseeki64 (Windows), fseeko (POSIX)
#if !defined(_WIN32)
#include <sys/types.h>  // off_t
#endif

namespace gravcal {

// ---------------------------------------------------------------------------
// Byte sources

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Reads up to n bytes into buf; returns how many. Fewer than n only at the
  // end of the input or on a read error; failed() tells the two apart.
  virtual std::size_t read(unsigned char* buf, std::size_t n) = 0;
  // A read error happened (the input did not end, it could not be read).
  virtual bool failed() const = 0;
  // Bytes delivered so far.
  virtual std::int64_t position() const = 0;
  // Total size in bytes where known (a regular file), else -1. Only a hint
  // (for progress, for checking a header's claims): never sizes memory.
  virtual std::int64_t size() const { return -1; }
  // Moves to an absolute byte position; false when the source cannot.
  virtual bool seek(std::int64_t) { return false; }
};

// R's NA for doubles (NA_real_): a NaN whose low 32 bits are 1954. Where
// GGIR's reader gives NA, a decoder in GGIR-compatible mode gives this (R's
// identical() tells NA from NaN).
inline double r_na_real() {
  const std::uint64_t bits = 0x7FF00000000007A2ULL;
  double v;
  std::memcpy(&v, &bits, sizeof v);
  return v;
}

// stdio's file position in 64 bits: std::fseek and std::ftell take a
// long, 32 bits on Windows (and 32-bit Linux), so a file over 2 GiB would
// lose its size and could not be seeked past 2 GiB. _fseeki64/_ftelli64
// on Windows (UCRT, msvcrt); fseeko/ftello elsewhere (off_t: 64 bits on
// 64-bit systems, and on 32-bit ones built with _FILE_OFFSET_BITS=64).
// Where the offset type is narrower than the position, the call fails
// rather than wrap.
inline bool file_seek64(std::FILE* f, std::int64_t pos, int whence) {
#if defined(_WIN32)
  return _fseeki64(f, static_cast<__int64>(pos), whence) == 0;
#else
  const off_t o = static_cast<off_t>(pos);
  if (static_cast<std::int64_t>(o) != pos) return false;
  return fseeko(f, o, whence) == 0;
#endif
}

// The position, or -1 when it cannot be told.
inline std::int64_t file_tell64(std::FILE* f) {
#if defined(_WIN32)
  const __int64 p = _ftelli64(f);
#else
  const off_t p = ftello(f);
#endif
  return p < 0 ? -1 : static_cast<std::int64_t>(p);
}

// A file, through stdio with a fixed buffer.
class FileSource : public ByteSource {
 public:
  explicit FileSource(const char* path) {
    f_ = std::fopen(path, "rb");
    if (f_ == nullptr) return;
    std::setvbuf(f_, nullptr, _IOFBF, 1u << 20);
    if (file_seek64(f_, 0, SEEK_END)) size_ = file_tell64(f_);
    file_seek64(f_, 0, SEEK_SET);
  }
  ~FileSource() override {
    if (f_ != nullptr) std::fclose(f_);
  }
  FileSource(const FileSource&) = delete;
  FileSource& operator=(const FileSource&) = delete;
  bool is_open() const { return f_ != nullptr; }
  std::size_t read(unsigned char* buf, std::size_t n) override {
    if (f_ == nullptr || n == 0) return 0;
    const std::size_t got = std::fread(buf, 1, n, f_);
    pos_ += static_cast<std::int64_t>(got);
    if (got < n && std::ferror(f_)) failed_ = true;
    return got;
  }
  bool failed() const override { return failed_; }
  std::int64_t position() const override { return pos_; }
  std::int64_t size() const override { return size_; }
  bool seek(std::int64_t pos) override {
    if (f_ == nullptr || pos < 0) return false;
    if (!file_seek64(f_, pos, SEEK_SET)) return false;
    pos_ = pos;
    return true;
  }

 private:
  std::FILE* f_ = nullptr;
  std::int64_t pos_ = 0;
  std::int64_t size_ = -1;
  bool failed_ = false;
};

// Bytes already in memory (tests, fuzzers); the caller keeps them alive.
class MemorySource : public ByteSource {
 public:
  MemorySource(const unsigned char* data, std::size_t n) : p_(data), n_(n) {}
  std::size_t read(unsigned char* buf, std::size_t n) override {
    const std::size_t k = n < n_ - at_ ? n : n_ - at_;
    if (k) std::memcpy(buf, p_ + at_, k);
    at_ += k;
    return k;
  }
  bool failed() const override { return false; }
  std::int64_t position() const override { return static_cast<std::int64_t>(at_); }
  std::int64_t size() const override { return static_cast<std::int64_t>(n_); }
  bool seek(std::int64_t pos) override {
    if (pos < 0 || static_cast<std::uint64_t>(pos) > n_) return false;
    at_ = static_cast<std::size_t>(pos);
    return true;
  }

 private:
  const unsigned char* p_;
  std::size_t n_;
  std::size_t at_ = 0;
};

// Reads exactly n bytes unless the input ends (or fails) first.
inline std::size_t read_full(ByteSource& src, unsigned char* buf, std::size_t n) {
  std::size_t got = 0;
  while (got < n) {
    const std::size_t k = src.read(buf + got, n - got);
    if (k == 0) break;
    got += k;
  }
  return got;
}

// Little-endian integers from bytes.
inline std::uint16_t le16(const unsigned char* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t le32(const unsigned char* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

// Days since 1970-01-01 of a date of the proleptic Gregorian calendar
// (H. Hinnant's days_from_civil), for the decoders' time stamps.
inline std::int64_t days_from_civil(std::int64_t y, unsigned m, unsigned d) {
  y -= m <= 2;
  const std::int64_t era = (y >= 0 ? y : y - 399) / 400;
  const unsigned yoe = static_cast<unsigned>(y - era * 400);
  const unsigned doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
  const unsigned doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
  return era * 146097 + static_cast<std::int64_t>(doe) - 719468;
}

// ---------------------------------------------------------------------------
// What a decoder gives

// What the file says about itself (from its header).
struct DeviceInfo {
  std::string format;   // "cwa", "geneactiv", "gt3x", "actigraph_csv", "csv"
  std::string device;   // model, as the header names it ("AX3", "GENEActiv 1.1")
  std::string serial;   // the device's serial number, "" when absent
  double sf = 0.0;      // sampling rate in Hz (of the samples the decoder gives)
  double start_time = std::numeric_limits<double>::quiet_NaN();  // s since 1970 UTC
  bool has_temperature = false;
  bool has_time = false;  // the decoder gives a time stamp per sample
  // the decoder gives a light value per sample (SampleBuffer::light): .cwa
  // and GENEActiv .bin; its units are the format decoder's (see there)
  bool has_light = false;
  // the decoder gives a wear flag per sample (SampleBuffer::wear: 1, 0, NaN
  // for none): an ad hoc csv file's wear column (option col_wear)
  bool has_wear = false;
  double range_g = std::numeric_limits<double>::quiet_NaN();  // +- full scale, g
  // the file's own text header, as stored, where the format has one (.gt3x:
  // info.txt; at most gt3x::kMaxInfo bytes); "" otherwise
  std::string header_text;
};

// What was read and what was skipped, and why. Counters have names chosen by
// each decoder ("bad_checksum", "malformed_lines", "gaps", ...) and keep their
// order of first use; notes hold the first few problems in words, with where
// they were (byte offset, line), for the user.
class Report {
 public:
  static constexpr std::size_t max_notes = 20;
  void count(const char* name, std::int64_t k = 1) {
    for (auto& c : counters) {
      if (c.first == name) {
        c.second += k;
        return;
      }
    }
    counters.emplace_back(name, k);
  }
  std::int64_t get(const char* name) const {
    for (const auto& c : counters) {
      if (c.first == name) return c.second;
    }
    return 0;
  }
  void note(std::string what) {
    ++notes_total;
    if (notes.size() < max_notes) notes.push_back(std::move(what));
  }
  std::int64_t units = 0;     // format units decoded (blocks, pages, lines, records)
  std::int64_t samples = 0;   // samples given to the caller
  std::int64_t skipped = 0;   // format units skipped as unusable
  std::int64_t gaps = 0;      // jumps in time
  double gap_seconds = 0.0;   // their total length
  bool truncated = false;     // the input ended inside a unit
  bool read_error = false;    // the input could not be read to its end
  std::vector<std::pair<std::string, std::int64_t>> counters;
  std::vector<std::string> notes;
  std::int64_t notes_total = 0;
};

// Arrays owned by the caller, each of `capacity` doubles; t, time and light
// may be null (then not written). The decoder appends at n.
//
// light is asked for by a caller that wants it and whose decoder says it has
// it (DeviceInfo::has_light); a null light costs the decoder nothing. A
// decoder without light never writes it (its caller leaves the column out),
// so put() does not touch it: the decoders with light write it themselves.
struct SampleBuffer {
  double* x = nullptr;
  double* y = nullptr;
  double* z = nullptr;
  double* t = nullptr;      // temperature, degrees C
  double* time = nullptr;   // seconds since 1970-01-01 UTC
  double* light = nullptr;  // the device's light value (DeviceInfo::has_light)
  // a wear flag (DeviceInfo::has_wear), asked and written as light is
  double* wear = nullptr;
  std::size_t capacity = 0;
  std::size_t n = 0;
  // The caller reads the times of the buffer's first row and of its last
  // two (the rows it holds when the read returns), no others: a decoder may
  // leave the other rows' times unwritten (GENEActiv's, whose per-sample
  // times cost a tenth of its decoding; g.getmeta()'s block store reads a
  // block's first and last times only).
  bool time_ends_only = false;
  bool full() const { return n >= capacity; }
  std::size_t room() const { return capacity - n; }
  // A buffer over consecutive columns of `cap` values at `base`: x, y, z,
  // then temperature, time and light when asked (base holds 3 to 6 columns).
  static SampleBuffer columns(double* base, std::size_t cap, bool temperature, bool with_time,
                              bool with_light = false) {
    SampleBuffer b;
    double* next = base;
    auto take = [&]() {
      double* c = next;
      next += cap;
      return c;
    };
    b.x = take();
    b.y = take();
    b.z = take();
    b.t = temperature ? take() : nullptr;
    b.time = with_time ? take() : nullptr;
    b.light = with_light ? take() : nullptr;
    b.capacity = cap;
    return b;
  }
  void put(double xi, double yi, double zi, double ti, double timei) {
    x[n] = xi;
    y[n] = yi;
    z[n] = zi;
    if (t != nullptr) t[n] = ti;
    if (time != nullptr) time[n] = timei;
    ++n;
  }
};

// Named options for a decoder (numbers and strings), set by the caller: for
// example "compat" = 1 for the reference reader's behaviour, or a csv's
// column layout. A decoder reads the ones it knows, with its own defaults.
class Options {
 public:
  void set(const std::string& name, double v) { num_.emplace_back(name, v); }
  void set(const std::string& name, const std::string& v) { str_.emplace_back(name, v); }
  double num(const char* name, double fallback) const {
    for (auto it = num_.rbegin(); it != num_.rend(); ++it) {
      if (it->first == name) return it->second;
    }
    return fallback;
  }
  bool has_num(const char* name) const {
    for (const auto& kv : num_) {
      if (kv.first == name) return true;
    }
    return false;
  }
  std::string str(const char* name, const std::string& fallback) const {
    for (auto it = str_.rbegin(); it != str_.rend(); ++it) {
      if (it->first == name) return it->second;
    }
    return fallback;
  }

 private:
  std::vector<std::pair<std::string, double>> num_;
  std::vector<std::pair<std::string, std::string>> str_;
};

// The reading rules every decoder and GGIR's resamplers share, read from
// the options in this one place: "compat" (1, the default: the reference
// reader's behaviour, GGIR's; 0 gravcal's own), "interpolation" (GGIR's
// interpolationType: 1 linear, the default, 2 nearest neighbour) and
// "resample_fused" (1 where GGIRread's compiled resample() fuses its
// multiply-adds: R/fp-build.R asks GGIRread).
struct ReadRules {
  bool compat = true;
  int interpolation = 1;
  bool fused = false;
  bool nearest() const { return interpolation == 2; }
  static ReadRules of(const Options& opts) {
    ReadRules r;
    r.compat = opts.num("compat", 1) != 0;
    r.interpolation = static_cast<int>(opts.num("interpolation", 1));
    r.fused = opts.num("resample_fused", 0) != 0;
    return r;
  }
};

// The UTC offset R's as.POSIXct() gives a calendar time in a zone (GGIR's
// configtz, else desiredtz: readAxivity's .cwa block times, read.myacc.csv's
// text time), as seconds to subtract from the calendar read as UTC: a step
// function of the calendar minute, with the minutes whose offset depends on
// R's earlier conversions (a time that exists twice, or not at all, at a
// change of offset) marked. R works it out in the R the package runs in
// (R/zone.R) and passes it as options: tz_n
// steps (tz_at_i: the calendar second from which tz_off_i holds; before
// the first, the first's offset), tz_amb_n marked spans [tz_amb_lo_j,
// tz_amb_hi_j). None: the calendar read as UTC. lubridate::force_tz()'s
// table (ActivPAL days; R/adhoc-csv.R) has no marks but spans of calendar
// times that do not exist in the zone, [tz_na_lo_k, tz_na_hi_k) for k <
// tz_na_n, whose offset is NaN (force_tz() gives NA there).
class ZoneTable {
 public:
  static constexpr int kMax = 4096;
  ZoneTable() = default;
  explicit ZoneTable(const Options& opts) {
    const double n = opts.num("tz_n", 0), na = opts.num("tz_amb_n", 0);
    if (!(n >= 1 && n <= kMax && na >= 0 && na <= kMax)) return;
    for (int i = 0; i < static_cast<int>(n); ++i) {
      const std::string k = std::to_string(i);
      at_.push_back(opts.num(("tz_at_" + k).c_str(), 0));
      off_.push_back(opts.num(("tz_off_" + k).c_str(), 0));
    }
    for (int j = 0; j < static_cast<int>(na); ++j) {
      const std::string k = std::to_string(j);
      amb_.emplace_back(opts.num(("tz_amb_lo_" + k).c_str(), 0), opts.num(("tz_amb_hi_" + k).c_str(), 0));
    }
    const double nn = opts.num("tz_na_n", 0);
    if (!(nn >= 0 && nn <= kMax)) return;
    for (int j = 0; j < static_cast<int>(nn); ++j) {
      const std::string k = std::to_string(j);
      na_.emplace_back(opts.num(("tz_na_lo_" + k).c_str(), 0), opts.num(("tz_na_hi_" + k).c_str(), 0));
    }
  }
  bool empty() const { return at_.empty(); }
  // the offset for calendar time c (seconds, read as UTC)
  double offset(double c) const {
    if (at_.empty()) return 0;
    for (const auto& a : na_) {
      if (c >= a.first && c < a.second) return std::numeric_limits<double>::quiet_NaN();
    }
    std::size_t lo = 0, hi = at_.size();  // the last step at or before c
    while (hi - lo > 1) {
      const std::size_t mid = lo + (hi - lo) / 2;
      if (at_[mid] <= c) lo = mid;
      else hi = mid;
    }
    return off_[lo];
  }
  bool ambiguous(double c) const {
    for (const auto& a : amb_) {
      if (c >= a.first && c < a.second) return true;
    }
    return false;
  }

 private:
  std::vector<double> at_, off_;
  std::vector<std::pair<double, double>> amb_;
  std::vector<std::pair<double, double>> na_;  // calendar times that do not exist (force_tz())
};

// The interface every format's decoder implements. A decoder is built on a
// ByteSource it does not own (which must outlive it) and its Options.
class Decoder {
 public:
  virtual ~Decoder() = default;
  // Reads the header. False when the input is not a readable file of this
  // format (the reason is in error()); then read() gives nothing.
  virtual bool open() = 0;
  // Decodes samples into out until out is full or `max_units` of the
  // format's units (cwa: 512-byte blocks; GENEActiv: pages; csv: lines;
  // gt3x: seconds) have been consumed; a negative max_units means no limit.
  // Returns the units consumed. Resumes where it stopped: a unit whose
  // samples did not all fit is finished by the next call before any new unit
  // is counted. done() is true once every sample has been given.
  virtual std::int64_t read(SampleBuffer& out, std::int64_t max_units) = 0;
  virtual bool done() const = 0;
  // An upper bound on the samples one unit gives, fixed by the format (not
  // read from the file); for sizing a block of `max_units` units.
  virtual std::size_t max_samples_per_unit() const = 0;
  // GGIR's epoch-level imputation of time gaps longer than its limit
  // (g.getmeta(); decode_ggir_timegaps.hpp): for each such gap in the
  // samples given since the last call, the sample (0-based, over every
  // sample this decoder has given) that carries GGIR's remaining_epochs,
  // and that number of short epochs. Empty for a decoder that imputes none.
  struct EpochGap {
    std::int64_t row;
    double remaining;
  };
  virtual std::vector<EpochGap> take_epoch_gaps() { return {}; }
  // The times of the first and of the last two samples of the latest read
  // of a number of units (one of GGIR's blocks, in one read() or several),
  // as they stand once that read has ended, for a decoder whose times of a
  // block depend on what comes at its end and so were given before they
  // were known (GENEActiv in GGIR's mode: readGENEActiv times a call by the
  // rate of its last page). False: the times as given stand.
  struct CallEndTimes {
    double first = std::numeric_limits<double>::quiet_NaN();
    double last[2] = {std::numeric_limits<double>::quiet_NaN(),
                      std::numeric_limits<double>::quiet_NaN()};  // the last, the one before
    int n_last = 0;  // how many of those two the read gave
  };
  virtual bool call_end_times(CallEndTimes&) const { return false; }
  // The file's units as they are stored, for a format whose reference
  // reader logs them (GGIRread's readParmayMatrix(): its QClog, a row per
  // packet): named columns of numbers, one value a unit, in the file's
  // order. Empty for a decoder that keeps no such log.
  struct UnitLog {
    std::vector<std::string> names;
    std::vector<std::vector<double>> columns;
  };
  virtual UnitLog unit_log() const { return {}; }
  const DeviceInfo& info() const { return info_; }
  const Report& report() const { return report_; }
  const std::string& error() const { return error_; }

 protected:
  DeviceInfo info_;
  Report report_;
  std::string error_;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_HPP
