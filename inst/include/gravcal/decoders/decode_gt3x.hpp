// gravcal: ActiGraph .gt3x decoder (a zip holding info.txt and log.bin, or on
// old NEO/MRA devices with firmware <= 2.5.0 info.txt and activity.bin).
//
// Sources: ActiGraph's GT3X-File-Format and NHANES-GT3X-File-Format
// documents (record layout, checksum, ACTIVITY / ACTIVITY2 / PARAMETERS
// payloads, activity.bin packing), PKWARE's APPNOTE (zip structures), and the
// behaviour of read.gt3x 1.2.0 (parseGT3X, parseActivityBin, get_n_samples,
// as.data.frame.activity), matched by tests, not copied.
//
// Unit = one second: a log.bin ACTIVITY/ACTIVITY2 record holding samples
// (what read.gt3x's batch_begin / batch_end count), or sf samples of
// activity.bin. Idle-sleep seconds and gaps are not units.
//
// compat = 1 (default, read.gt3x) versus compat = 0 (specification):
// - scale: info.txt "Acceleration Scale", else 341 (NEO, CLE, MRA) or 256
//   (MOS, TAS) | compat 0: the PARAMETERS record's ACCEL_SCALE when present.
// - time of sample i of a record stamped ts: start + ((u32)(ts - trunc(start))
//   + i * (1 / sf)) * 100 / 100, start from info.txt's ticks as R computes it
//   | compat 0: ts + i / sf.
// - impute_zeroes = 1 (read.gt3x(imputeZeroes = TRUE) read whole): at most
//   max_samples = (Last Sample Time - Start Date) * sf samples, then the rest
//   of the file is not read, and zeros pad to max_samples at the end
//   | compat 0: no cap and no padding.
// Both: values are counts / scale rounded to 3 decimals (half away from
// zero); idle-sleep records (ACTIVITY with fewer bytes than one sample) are a
// second of zeros with impute_zeroes = 1; records are taken in the order of
// the file and an ACTIVITY record's YXZ order is honoured per record
// (read.gt3x names the columns once per file, so a file mixing ACTIVITY and
// ACTIVITY2 records differs).
//
// Damage (both modes; read.gt3x does not check): a record whose checksum
// fails, whose separator is missing, or whose size runs past the end is
// skipped and the stream resynchronised on the next record that checks (one
// count per damaged stretch); nonzero bytes between records are counted.
// Time stamps: a record stamped before info.txt's start, or (impute_zeroes =
// 1) more than a second past the end that info.txt allows (max_samples / sf
// after the start), is skipped ("bad_timestamp"): so a damaged stamp never
// opens a gap longer than the recording, and imputed zeros never pass
// max_samples. With impute_zeroes = 0 records past that end are kept, as
// read.gt3x's batches keep them ("past_last_sample_time"). A jump forward
// that the next activity record does not follow (it is stamped between the
// expected time and the jump) is a damaged stamp: the record is kept at the
// expected time ("bad_timestamp", no gap). Other forward jumps are gaps
// (counted; zeros only with impute_zeroes = 1, a chunk at a time); backward
// jumps are kept, as read.gt3x keeps them, and counted ("time_backwards").
// Differences from read.gt3x: impute_zeroes = 0 follows its batch reads, so
// a whole read with imputeZeroes = FALSE of a file with records past info.txt's
// end (its max_samples cap) differs; a batch's own cap (max_samples samples
// in one batch) is not applied; on damaged files it fails (index out of
// bounds) when a gap passes max_samples in a whole read, and keeps records
// whose checksum fails.
//
// The code: the zip structures and info.txt are read by the functions of
// namespace gt3x; gt3x::ZipReader finds the entries and opens them as byte
// sources (inflated through the EntryInflater when deflated);
// gt3x::RecordStream reads the data entry through one buffer and frames
// log.bin's records, resynchronising after damage; Gt3xDecoder applies
// read.gt3x's rules to the records: the time of each sample, the cap at
// info.txt's end, idle-sleep and gap zeros, and the checks of the stamps.
#ifndef GRAVCAL_DECODE_GT3X_HPP
#define GRAVCAL_DECODE_GT3X_HPP

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "gravcal/decoders/decode.hpp"

namespace gravcal {

// What the decoder needs from outside the core: the inflated bytes of a
// deflated zip entry. `raw` gives the entry's raw deflate stream (RFC 1951)
// and outlives the returned source. The glue implements it with zlib.
class EntryInflater {
 public:
  virtual ~EntryInflater() = default;
  virtual std::unique_ptr<ByteSource> open(ByteSource& raw) = 0;
};

namespace gt3x {

// zip (PKWARE APPNOTE 4.3.7, 4.3.12, 4.3.16; zip64: 4.3.14, 4.3.15, 4.5.3)
constexpr std::uint32_t kLocalSig = 0x04034b50u;
constexpr std::uint32_t kCentralSig = 0x02014b50u;
constexpr std::uint32_t kEndSig = 0x06054b50u;
constexpr std::uint32_t kZip64EndSig = 0x06064b50u;
constexpr std::uint32_t kZip64LocatorSig = 0x07064b50u;
constexpr std::size_t kLocalLen = 30, kCentralLen = 46, kEndLen = 22;
constexpr std::size_t kZip64EndLen = 56, kZip64LocatorLen = 20;
constexpr std::uint16_t kZip64Extra = 0x0001;  // zip64 extended information
// zip64's marker: the field's value is in the zip64 structures
constexpr std::uint32_t kMark32 = 0xFFFFFFFFu;
constexpr std::uint16_t kMark16 = 0xFFFFu;
// A zip64 size or offset above this (64 PiB) is damage; it keeps the sums of
// sizes and offsets far from overflow.
constexpr std::int64_t kMaxZip64 = std::int64_t{1} << 56;
constexpr std::size_t kMaxComment = 65535;
constexpr int kMaxEntries = 1000;          // entries looked at
constexpr std::size_t kMaxName = 1024;     // entry name bytes kept
constexpr std::size_t kMaxInfo = 1 << 16;  // info.txt bytes read
constexpr std::uint16_t kStored = 0, kDeflated = 8;

// log.bin records (GT3X-File-Format README)
constexpr unsigned char kSeparator = 0x1E;
constexpr std::size_t kHeaderLen = 8;  // separator, type, u32 time, u16 size
constexpr std::size_t kMaxRecord = kHeaderLen + 65535 + 1;
constexpr unsigned char kActivity = 0x00, kBattery = 0x02, kEvent = 0x03,
                        kHeartRate = 0x04, kLux = 0x05, kMetadata = 0x06,
                        kTag = 0x07, kEpoch = 0x09, kHeartRateAnt = 0x0B,
                        kEpoch2 = 0x0C, kCapsense = 0x0D, kHeartRateBle = 0x0E,
                        kEpoch3 = 0x0F, kEpoch4 = 0x10, kFifoError = 0x13,
                        kFifoDump = 0x14, kParameters = 0x15,
                        kSensorSchema = 0x18, kSensorData = 0x19,
                        kActivity2 = 0x1A;
// PARAMETERS keys (LogRecords/Parameters.md): address, identifier
constexpr std::uint16_t kAddrDevice = 0, kKeyAccelScale = 55;
constexpr std::uint16_t kAddrConfig = 1, kKeyStartTime = 12;

constexpr int kMaxRate = 256;   // Hz; ActiGraph devices sample 30..100 Hz
constexpr double kTimeUnit = 100.0;  // read.gt3x's time index: 1/100 s
// .NET ticks (100 ns since 0001-01-01) to Unix seconds, as R does it:
// as.POSIXct(ticks / 1e7, origin = "0001-01-01", tz = "GMT")
constexpr double kTicksPerSecond = 1e7;
constexpr double kEpoch0001 = -62135596800.0;
constexpr double kFallbackDays = 100.0;  // get_n_samples() without an end
constexpr std::size_t kBufLen = 1 << 18;  // record buffer (>= 2 records)
constexpr int kPeekRecords = 8;           // records looked ahead past a jump
constexpr std::size_t kInfoLines = 200;

inline bool known_type(unsigned char t) {
  switch (t) {
    case kActivity: case kBattery: case kEvent: case kHeartRate: case kLux:
    case kMetadata: case kTag: case kEpoch: case kHeartRateAnt: case kEpoch2:
    case kCapsense: case kHeartRateBle: case kEpoch3: case kEpoch4:
    case kFifoError: case kFifoDump: case kParameters: case kSensorSchema:
    case kSensorData: case kActivity2:
      return true;
    default:
      return false;
  }
}

// PARAMETERS float: 24-bit two's-complement fraction / 2^23 times 2^exponent
// (signed top byte); 0x007FFFFF and 0x00800000 stand for +- the maximum.
inline double decode_param_float(std::uint32_t v) {
  if (v == 0x007FFFFFu || v == 0x00800000u) return std::numeric_limits<double>::quiet_NaN();
  std::int32_t e = static_cast<std::int32_t>((v >> 24) & 0xFFu);
  if (e & 0x80) e -= 256;
  std::int32_t f = static_cast<std::int32_t>(v & 0x00FFFFFFu);
  if (f & 0x00800000) f -= 0x01000000;
  return f / 8388608.0 * std::pow(2.0, e);
}

// One zip entry as the central directory (or its local header) gives it.
struct ZipEntry {
  bool found = false;
  bool zip64 = false;  // sizes or offset from its zip64 extra field
  std::uint16_t method = 0;
  std::uint16_t flags = 0;
  std::int64_t comp_size = 0, size = 0, local_offset = 0;
  std::string name;
};

inline std::uint64_t le64(const unsigned char* p) {
  return static_cast<std::uint64_t>(le32(p)) | (static_cast<std::uint64_t>(le32(p + 4)) << 32);
}

// A window [start, start + len) of a source, read sequentially.
class WindowSource : public ByteSource {
 public:
  WindowSource(ByteSource& base, std::int64_t start, std::int64_t len)
      : base_(base), len_(len) {
    ok_ = base_.seek(start);
  }
  std::size_t read(unsigned char* buf, std::size_t n) override {
    if (!ok_) return 0;
    const std::int64_t left = len_ - pos_;
    if (left <= 0) return 0;
    if (static_cast<std::int64_t>(n) > left) n = static_cast<std::size_t>(left);
    const std::size_t k = base_.read(buf, n);
    pos_ += static_cast<std::int64_t>(k);
    return k;
  }
  bool failed() const override { return !ok_ || base_.failed(); }
  std::int64_t position() const override { return pos_; }
  std::int64_t size() const override { return len_; }
  // The window ended before its length: the file is cut short.
  bool short_read() const { return pos_ < len_; }

 private:
  ByteSource& base_;
  std::int64_t len_;
  std::int64_t pos_ = 0;
  bool ok_ = false;
};

}  // namespace gt3x

namespace gt3x {

// The entries a .gt3x needs, from the central directory; when the directory
// is unreadable, from the local file headers read from byte 0 (a cut or
// damaged end). Reads only fixed-size pieces; never sizes memory by a field.
// `error`: why the directory or a local header could not be used (zip64
// structures missing or inconsistent), for the decoder's message.
struct ZipEntries {
  ZipEntry info, log, activity;
  bool from_local_headers = false;
  std::string error;
};

inline bool wanted_entry(const std::string& name) {
  return name == "info.txt" || name == "log.bin" || name == "activity.bin";
}

inline void keep_entry(ZipEntries& z, const std::string& name, const ZipEntry& e) {
  if (name == "info.txt" && !z.info.found) z.info = e;
  else if (name == "log.bin" && !z.log.found) z.log = e;
  else if (name == "activity.bin" && !z.activity.found) z.activity = e;
}

// A zip header's flags, method and sizes, which stand in the same order in
// a central directory header and a local one, from `p` (the flags' offset).
inline ZipEntry zip_entry_at(const unsigned char* p) {
  ZipEntry e;
  e.found = true;
  e.flags = le16(p);
  e.method = le16(p + 2);
  e.comp_size = le32(p + 12);
  e.size = le32(p + 16);
  return e;
}

// The fields of a header that hold zip64's marker (0xFFFFFFFF, the disk
// number 0xFFFF): their values stand in its zip64 extra field, in this
// order (APPNOTE 4.5.3).
struct Zip64Marks {
  bool size = false, comp = false, offset = false, disk = false;
  bool any() const { return size || comp || offset || disk; }
};

// Reads the zip64 extra field (id 0x0001) among a header's `elen` bytes of
// extra fields at byte `at`, and takes from it the values `m` marks: into
// e.size, e.comp_size, e.local_offset and `disk`. In a local header both
// sizes stand there when either is marked (APPNOTE 4.5.3); a field of 8
// bytes where only one is marked is taken as that one. False, with `why`,
// when the field is absent, too short or holds a value out of range. Reads
// at most 28 bytes of the field.
inline bool read_zip64_extra(ByteSource& src, std::int64_t at, std::size_t elen,
                             const Zip64Marks& m, bool local, ZipEntry& e,
                             std::uint32_t& disk, std::string& why) {
  std::size_t pos = 0;
  unsigned char h[4];
  unsigned char d[28];
  while (pos + 4 <= elen) {
    if (!src.seek(at + static_cast<std::int64_t>(pos)) || read_full(src, h, 4) != 4) {
      why = "its extra field cannot be read";
      return false;
    }
    const std::size_t len = le16(h + 2);
    if (pos + 4 + len > elen) break;  // a record past the extra field's end
    if (le16(h) != kZip64Extra) {
      pos += 4 + len;
      continue;
    }
    const std::size_t k = std::min(len, sizeof d);
    if (read_full(src, d, k) != k) {
      why = "its zip64 extra field cannot be read";
      return false;
    }
    const bool both = local && (m.size || m.comp) && k >= 16;
    std::size_t q = 0;
    int need = 0;
    auto take = [&](std::int64_t& v, const char* what) {
      ++need;
      if (q + 8 > k) return false;
      const std::uint64_t u = le64(d + q);
      q += 8;
      if (u > static_cast<std::uint64_t>(kMaxZip64)) {
        why = std::string("its zip64 ") + what + " " + std::to_string(u) + " is out of range";
        return false;
      }
      v = static_cast<std::int64_t>(u);
      return true;
    };
    bool ok = true;
    if (ok && (m.size || both)) ok = take(e.size, "size");
    if (ok && (m.comp || both)) ok = take(e.comp_size, "compressed size");
    if (ok && m.offset) ok = take(e.local_offset, "local header offset");
    if (ok && m.disk) {
      ++need;
      ok = q + 4 <= k;
      if (ok) disk = le32(d + q);
    }
    if (!ok && why.empty()) {
      why = "its zip64 extra field holds " + std::to_string(k) + " bytes, too few for the " +
            std::to_string(need) + " value(s) marked 0xFFFFFFFF / 0xFFFF in the header";
    }
    return ok;
  }
  why = "its header marks sizes or offsets as zip64's (0xFFFFFFFF / 0xFFFF) but it has no "
        "zip64 extra field (0x0001) with their values";
  return false;
}

// The end-of-central-directory record: searched in the last 64 KiB + 22;
// with zip64 (its values marked 0xFFFF / 0xFFFFFFFF, or a zip64 locator just
// before it) the directory's offset and entry count from the zip64 end
// record the locator points to. False, with `why` for a damaged zip64 end.
inline bool find_end_record(ByteSource& src, std::int64_t& cd_offset, int& n_entries,
                            std::string& why) {
  const std::int64_t size = src.size();
  if (size < static_cast<std::int64_t>(kEndLen)) return false;
  const std::int64_t tail = std::min<std::int64_t>(size, kEndLen + kMaxComment);
  std::vector<unsigned char> buf(static_cast<std::size_t>(tail));
  if (!src.seek(size - tail) || read_full(src, buf.data(), buf.size()) != buf.size()) return false;
  for (std::int64_t i = tail - static_cast<std::int64_t>(kEndLen); i >= 0; --i) {
    const unsigned char* p = buf.data() + i;
    if (le32(p) != kEndSig) continue;
    if (i + static_cast<std::int64_t>(kEndLen) + le16(p + 20) > tail) continue;
    const std::int64_t at = size - tail + i;  // the record's byte in the file
    std::int64_t off = le32(p + 16);
    std::int64_t n = le16(p + 10);
    const bool marked = le16(p + 4) == kMark16 || le16(p + 6) == kMark16 || le16(p + 8) == kMark16 ||
                        le16(p + 10) == kMark16 || le32(p + 12) == kMark32 || le32(p + 16) == kMark32;
    unsigned char loc[kZip64LocatorLen];
    const std::int64_t loc_at = at - static_cast<std::int64_t>(kZip64LocatorLen);
    const bool has_loc = loc_at >= 0 && src.seek(loc_at) &&
                         read_full(src, loc, kZip64LocatorLen) == kZip64LocatorLen &&
                         le32(loc) == kZip64LocatorSig;
    if (has_loc) {
      const std::uint64_t rec = le64(loc + 8);
      unsigned char r[kZip64EndLen];
      const bool found = rec <= static_cast<std::uint64_t>(loc_at) &&
                         static_cast<std::int64_t>(rec) + static_cast<std::int64_t>(kZip64EndLen) <= loc_at &&
                         src.seek(static_cast<std::int64_t>(rec)) &&
                         read_full(src, r, kZip64EndLen) == kZip64EndLen && le32(r) == kZip64EndSig;
      if (found) {
        if (le32(r + 16) != 0 || le32(r + 20) != 0) {
          why = "zip64 end of central directory record on disk " + std::to_string(le32(r + 16)) +
                " (split archives are not read)";
          return false;
        }
        const std::uint64_t n64 = le64(r + 32), off64 = le64(r + 48);
        n = static_cast<std::int64_t>(std::min<std::uint64_t>(n64, kMaxEntries + 1));
        off = off64 < static_cast<std::uint64_t>(size) ? static_cast<std::int64_t>(off64) : size;
      } else if (marked) {
        why = "zip64 end of central directory record not found at byte " + std::to_string(rec) +
              ", where its locator points";
        return false;
      }
    } else if (marked) {
      why = "the end of central directory record marks its values as zip64's (0xFFFF / "
            "0xFFFFFFFF) but no zip64 locator precedes it";
      return false;
    }
    cd_offset = off;
    n_entries = static_cast<int>(n);
    if (cd_offset >= size && (has_loc || marked)) {
      why = "zip64 central directory offset beyond the file's " + std::to_string(size) + " bytes";
    }
    return cd_offset < size;
  }
  return false;
}

inline bool read_central_directory(ByteSource& src, ZipEntries& z) {
  std::int64_t off = 0;
  int n = 0;
  if (!find_end_record(src, off, n, z.error) || !src.seek(off)) return false;
  const std::int64_t cd = off;
  unsigned char h[kCentralLen];
  char name[kMaxName];
  for (int i = 0; i < n && i < kMaxEntries; ++i) {
    if (read_full(src, h, kCentralLen) != kCentralLen || le32(h) != kCentralSig) return false;
    const std::size_t nlen = le16(h + 28), elen = le16(h + 30), clen = le16(h + 32);
    const std::size_t keep = std::min(nlen, kMaxName);
    if (read_full(src, reinterpret_cast<unsigned char*>(name), keep) != keep) return false;
    ZipEntry e = zip_entry_at(h + 8);
    e.local_offset = le32(h + 42);
    e.name.assign(name, keep);
    Zip64Marks m;
    m.size = le32(h + 24) == kMark32;
    m.comp = le32(h + 20) == kMark32;
    m.offset = le32(h + 42) == kMark32;
    m.disk = le16(h + 34) == kMark16;
    if (m.any() && wanted_entry(e.name)) {
      std::uint32_t disk = 0;
      std::string why;
      if (!read_zip64_extra(src, off + static_cast<std::int64_t>(kCentralLen + nlen), elen, m,
                            false, e, disk, why)) {
        z.error = "the central directory's " + e.name + ": " + why;
        return false;
      }
      if (disk != 0) {
        z.error = "the central directory's " + e.name + " starts on disk " + std::to_string(disk) +
                  " (split archives are not read)";
        return false;
      }
      if (e.local_offset >= cd) {
        z.error = "the central directory's " + e.name + ": its local header offset " +
                  std::to_string(e.local_offset) + " is not before the directory (byte " +
                  std::to_string(cd) + ")";
        return false;
      }
      if (e.local_offset + static_cast<std::int64_t>(kLocalLen) + e.comp_size > cd) {
        z.error = "the central directory's " + e.name + ": its " + std::to_string(e.comp_size) +
                  " stored bytes from byte " + std::to_string(e.local_offset) +
                  " run past the directory (byte " + std::to_string(cd) + ")";
        return false;
      }
      e.zip64 = true;
    }
    off += static_cast<std::int64_t>(kCentralLen + nlen + elen + clen);
    keep_entry(z, e.name, e);
    if (!src.seek(off)) return false;
  }
  return z.info.found || z.log.found || z.activity.found;
}

// Walks the local file headers from byte 0 while their sizes are known.
// A header whose sizes are zip64's (marked 0xFFFFFFFF) takes them from its
// zip64 extra field; without one the walk stops there, with z.error.
inline bool read_local_headers(ByteSource& src, ZipEntries& z) {
  std::int64_t off = 0;
  unsigned char h[kLocalLen];
  char name[kMaxName];
  for (int i = 0; i < kMaxEntries; ++i) {
    if (!src.seek(off) || read_full(src, h, kLocalLen) != kLocalLen || le32(h) != kLocalSig) break;
    const std::size_t nlen = le16(h + 26), elen = le16(h + 28);
    const std::size_t keep = std::min(nlen, kMaxName);
    if (read_full(src, reinterpret_cast<unsigned char*>(name), keep) != keep) break;
    ZipEntry e = zip_entry_at(h + 6);
    e.local_offset = off;
    e.name.assign(name, keep);
    const bool sizes_later = (e.flags & 0x08) != 0 && e.comp_size == 0;  // data descriptor
    Zip64Marks m;
    m.size = le32(h + 22) == kMark32;
    m.comp = le32(h + 18) == kMark32;
    if (!sizes_later && m.any()) {
      std::uint32_t disk = 0;
      std::string why;
      if (!read_zip64_extra(src, off + static_cast<std::int64_t>(kLocalLen + nlen), elen, m, true,
                            e, disk, why)) {
        z.error = "the local header of " + e.name + " at byte " + std::to_string(off) + ": " + why;
        break;
      }
      e.zip64 = true;
    }
    if (sizes_later) e.comp_size = -1;
    keep_entry(z, e.name, e);
    if (sizes_later) break;
    off += static_cast<std::int64_t>(kLocalLen + nlen + elen) + e.comp_size;
  }
  z.from_local_headers = true;
  return z.info.found || z.log.found || z.activity.found;
}

// Where an entry's data starts (after its local header), or -1 with `why`.
// An entry the central directory gives with zip64 values must have a local
// header whose sizes (its own zip64 ones when marked) are the same.
inline std::int64_t entry_data_offset(ByteSource& src, const ZipEntry& e, std::string& why) {
  unsigned char h[kLocalLen];
  if (!src.seek(e.local_offset) || read_full(src, h, kLocalLen) != kLocalLen ||
      le32(h) != kLocalSig) {
    why = "zip entry's local header not found at byte " + std::to_string(e.local_offset);
    return -1;
  }
  const std::size_t nlen = le16(h + 26), elen = le16(h + 28);
  const std::int64_t data = e.local_offset + static_cast<std::int64_t>(kLocalLen + nlen + elen);
  ZipEntry l = zip_entry_at(h + 6);
  if (e.zip64 && e.comp_size >= 0 && (l.flags & 0x08) == 0) {
    Zip64Marks m;
    m.size = le32(h + 22) == kMark32;
    m.comp = le32(h + 18) == kMark32;
    std::uint32_t disk = 0;
    std::string w;
    if (m.any() && !read_zip64_extra(src, e.local_offset + static_cast<std::int64_t>(kLocalLen + nlen),
                                     elen, m, true, l, disk, w)) {
      why = "the local header of " + e.name + " at byte " + std::to_string(e.local_offset) + ": " + w;
      return -1;
    }
    if (l.comp_size != e.comp_size || l.size != e.size) {
      why = "inconsistent zip64 sizes of " + e.name + ": " + std::to_string(l.comp_size) +
            " stored bytes (" + std::to_string(l.size) + " inflated) in its local header, " +
            std::to_string(e.comp_size) + " (" + std::to_string(e.size) +
            ") in the central directory";
      return -1;
    }
  }
  return data;
}

// Days-from-civil arithmetic is not needed: ticks and Unix seconds are both
// counts. Parses a decimal tick count; false when not all digits.
inline bool parse_ticks(const std::string& s, double& seconds) {
  if (s.empty() || s.size() > 19) return false;
  std::uint64_t v = 0;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<std::uint64_t>(c - '0');
  }
  // R: as.double(ticks) / 1e7, then origin 0001-01-01 added
  seconds = kEpoch0001 + static_cast<double>(v) / kTicksPerSecond;
  return true;
}

inline bool parse_number(const std::string& s, double& v) {
  if (s.empty()) return false;
  char* end = nullptr;
  v = std::strtod(s.c_str(), &end);
  while (end != nullptr && (*end == ' ' || *end == '\t')) ++end;
  return end != nullptr && *end == '\0' && std::isfinite(v);
}

// info.txt: "Key: Value" lines (GT3X-File-Format info.txt.md).
struct Info {
  std::vector<std::pair<std::string, std::string>> kv;
  const std::string* get(const char* key) const {
    for (const auto& p : kv) {
      if (p.first == key) return &p.second;
    }
    return nullptr;
  }
  void parse(const std::string& text) {
    std::size_t at = 0;
    while (at < text.size() && kv.size() < kInfoLines) {
      std::size_t nl = text.find('\n', at);
      if (nl == std::string::npos) nl = text.size();
      std::string line = text.substr(at, nl - at);
      at = nl + 1;
      while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
      const std::size_t sep = line.find(": ");
      if (sep == std::string::npos) continue;
      const std::size_t next = line.find(": ", sep + 2);  // R's strsplit keeps piece 2
      kv.emplace_back(line.substr(0, sep),
                      line.substr(sep + 2, next == std::string::npos ? std::string::npos
                                                                    : next - sep - 2));
    }
  }
};

// Firmware "a.b.c" <= 2.5.0 (read.gt3x's old_version(), with NEO / MRA).
inline bool firmware_at_most_2_5_0(const std::string& fw) {
  int v[3] = {0, 0, 0};
  std::size_t at = 0;
  for (int i = 0; i < 3 && at <= fw.size(); ++i) {
    const std::size_t dot = fw.find('.', at);
    v[i] = std::atoi(fw.substr(at, dot == std::string::npos ? std::string::npos : dot - at).c_str());
    if (dot == std::string::npos) break;
    at = dot + 1;
  }
  if (v[0] != 2) return v[0] < 2;
  if (v[1] != 5) return v[1] < 5;
  return v[2] <= 0;
}

// Twelve-bit two's-complement value k of a packed stream whose first value
// starts at nibble `nib0` of p (big-endian nibbles, Activity.md).
inline int unpack12(const unsigned char* p, std::size_t nib) {
  const unsigned char* b = p + (nib >> 1);
  int v = (nib & 1u) ? (((b[0] & 0x0F) << 8) | b[1]) : ((b[0] << 4) | (b[1] >> 4));
  return (v & 0x800) ? v - 4096 : v;
}

// The entries of a .gt3x's zip as byte sources: found from the central
// directory (else from the local headers), and each opened as a window on
// its stored bytes, inflated when deflated. Owns the sources it opens; the
// zip and the inflater must outlive it. Where it fails, `error` says why,
// in the words of the decoder's error().
class ZipReader {
 public:
  // `inflater` reads deflated entries (null: only stored entries can be read).
  ZipReader(ByteSource& zip, EntryInflater* inflater) : zip_(zip), inflater_(inflater) {}

  // info.txt, log.bin and activity.bin, from the central directory; when
  // it is unreadable, from the local headers, which is counted and noted in
  // `report` ("zip_directory_damaged").
  bool find_entries(ZipEntries& z, Report& report, std::string& error) {
    if (!read_central_directory(zip_, z)) {
      const std::string cd_why = z.error;
      z = ZipEntries();
      if (!read_local_headers(zip_, z)) {
        if (!z.error.empty()) {
          return fail(error, z.error + (cd_why.empty() ? "" : "; and " + cd_why));
        }
        if (!cd_why.empty()) return fail(error, cd_why + ", and no readable local file header at byte 0");
        return fail(error, "not a zip file (no readable central directory, no local file header at byte 0)");
      }
      report.count("zip_directory_damaged");
      report.note("zip central directory unreadable" + (cd_why.empty() ? "" : " (" + cd_why + ")") +
                  ": entries found from their local headers");
    }
    return true;
  }

  // A byte source for an entry's (inflated) bytes.
  bool open_entry(const ZipEntry& e, ByteSource*& src, std::string& error) {
    std::string why;
    const std::int64_t at = entry_data_offset(zip_, e, why);
    if (at < 0) return fail(error, why);
    const std::int64_t len = e.comp_size >= 0 ? e.comp_size : std::max<std::int64_t>(0, zip_.size() - at);
    windows_.emplace_back(new WindowSource(zip_, at, len));
    WindowSource* w = windows_.back().get();
    if (e.method == kStored) {
      src = w;
      return true;
    }
    if (e.method != kDeflated) {
      return fail(error, "zip entry compressed with method " + std::to_string(e.method) +
                         " (only stored and deflated are read)");
    }
    if (inflater_ == nullptr) return fail(error, "zip entry is deflated and no inflater was given");
    inflated_.push_back(inflater_->open(*w));
    src = inflated_.back().get();
    if (src == nullptr) return fail(error, "cannot inflate zip entry");
    return true;
  }

  // info.txt's text (at most kMaxInfo bytes).
  bool read_small_entry(const ZipEntry& e, std::string& text, std::string& error) {
    ByteSource* src = nullptr;
    if (!open_entry(e, src, error)) return false;
    std::vector<unsigned char> b(kMaxInfo);
    const std::size_t k = read_full(*src, b.data(), b.size());
    text.assign(reinterpret_cast<const char*>(b.data()), k);
    if (windows_.back()->short_read()) {
      return fail(error, "info.txt cut short at byte " + std::to_string(windows_.back()->position()) +
                         " of " + std::to_string(windows_.back()->size()) + " (the file ends there)");
    }
    if (k == 0) return fail(error, "info.txt is empty or unreadable");
    return true;
  }

  // The window on the stored bytes of the entry opened last.
  WindowSource* last_window() const { return windows_.back().get(); }

 private:
  static bool fail(std::string& error, const std::string& why) {
    error = why;
    return false;
  }

  ByteSource& zip_;
  EntryInflater* inflater_;
  std::vector<std::unique_ptr<WindowSource>> windows_;
  std::vector<std::unique_ptr<ByteSource>> inflated_;
};

// The data entry (log.bin, or activity.bin) read through one buffer, and
// log.bin's records in it: each record's separator, size and checksum
// checked, and after damage the stream resynchronised on the next record
// that checks (each damaged stretch counted and noted in the decoder's
// report, which must outlive this).
class RecordStream {
 public:
  explicit RecordStream(Report& report) : report_(report) {}

  // Starts reading `data`, the entry's bytes (`window`: its stored bytes in
  // the zip, which tell a file cut short). After damage a record is taken
  // only when stamped from a day before info.txt's start (`start_u32`) to a
  // day after `bound_secs` seconds past it.
  void start(ByteSource* data, WindowSource* window, std::uint32_t start_u32, std::int64_t bound_secs) {
    data_ = data;
    window_ = window;
    start_u32_ = start_u32;
    bound_secs_ = bound_secs;
    buf_.assign(kBufLen, 0);
  }
  bool started() const { return data_ != nullptr; }

  // The buffered bytes from the read position, buffered() of them (at
  // least n after ensure(n) is true; valid until the next ensure()).
  const unsigned char* here() const { return buf_.data() + beg_; }
  std::size_t buffered() const { return end_ - beg_; }
  void advance(std::size_t n) { beg_ += n; }
  // The read position, and the end of the buffered bytes, as byte offsets
  // in the entry.
  std::int64_t offset() const { return buf_off_ + static_cast<std::int64_t>(beg_); }
  std::int64_t buffered_end() const { return buf_off_ + static_cast<std::int64_t>(end_); }

  // At least n bytes from beg_ in the buffer, unless the input ends first.
  bool ensure(std::size_t n) {
    if (end_ - beg_ >= n) return true;
    if (beg_ + n > buf_.size()) {
      std::memmove(buf_.data(), buf_.data() + beg_, end_ - beg_);
      buf_off_ += static_cast<std::int64_t>(beg_);
      end_ -= beg_;
      beg_ = 0;
    }
    while (end_ - beg_ < n && !eof_) {
      const std::size_t k = data_->read(buf_.data() + end_, buf_.size() - end_);
      if (k == 0) {
        eof_ = true;
        const std::int64_t at = buf_off_ + static_cast<std::int64_t>(end_);
        if (window_ != nullptr && window_->short_read()) {  // the file is cut short
          report_.truncated = true;
          report_.note("zip entry cut short: " + std::to_string(window_->position()) + " of " +
                       std::to_string(window_->size()) + " stored bytes (" + std::to_string(at) +
                       " bytes of data)");
        } else if (data_->failed()) {
          report_.read_error = true;
          report_.note("read error (or corrupt deflate data) in the data entry at byte " + std::to_string(at));
        }
      }
      end_ += k;
    }
    return end_ - beg_ >= n;
  }

  // The next record that checks, at beg_; false at the end of the input.
  bool next_record() {
    for (;;) {
      if (!ensure(1)) {
        end_resync(true);
        return false;
      }
      const unsigned char b = buf_[beg_];
      if (b != kSeparator) {
        if (!resync_) {
          if (b == 0) {  // zero bytes between records happen (README): ignored
            ++beg_;
            continue;
          }
          start_resync("bad_separator");
        }
        const void* q = std::memchr(buf_.data() + beg_, kSeparator, end_ - beg_);
        beg_ = q ? static_cast<std::size_t>(static_cast<const unsigned char*>(q) - buf_.data()) : end_;
        continue;
      }
      if (!ensure(kHeaderLen + 1) ||
          !ensure(kHeaderLen + 1 + le16(buf_.data() + beg_ + 6))) {
        start_resync("record_past_end");
        ++beg_;
        continue;
      }
      const unsigned char* p = buf_.data() + beg_;
      const std::size_t size = le16(p + 6);
      unsigned char x = 0;
      for (std::size_t i = 0; i < kHeaderLen + size; ++i) x ^= p[i];
      if (static_cast<unsigned char>(~x) != p[kHeaderLen + size]) {
        start_resync("bad_checksum");
        ++beg_;
        continue;
      }
      if (resync_ && (!known_type(p[1]) || !plausible_time(le32(p + 2)))) {
        ++beg_;  // a chance match inside damaged bytes
        continue;
      }
      end_resync(false);
      return true;
    }
  }

  // The time stamp of the next ACTIVITY / ACTIVITY2 record after beg_, if
  // the records up to it check; looks a few records ahead in the buffer.
  bool peek_activity_time(std::uint32_t& ts) {
    std::size_t at = 0;
    for (int i = 0; i < kPeekRecords; ++i) {
      if (at + kMaxRecord > kBufLen || !ensure(at + kHeaderLen + 1)) return false;
      const unsigned char* p = buf_.data() + beg_ + at;
      const std::size_t size = le16(p + 6);
      if (p[0] != kSeparator || !ensure(at + kHeaderLen + size + 1)) return false;
      p = buf_.data() + beg_ + at;
      unsigned char x = 0;
      for (std::size_t j = 0; j < kHeaderLen + size; ++j) x ^= p[j];
      if (static_cast<unsigned char>(~x) != p[kHeaderLen + size]) return false;
      if (p[1] == kActivity || p[1] == kActivity2) {
        ts = le32(p + 2);
        return true;
      }
      at += kHeaderLen + size + 1;
    }
    return false;
  }

 private:
  void start_resync(const char* why) {
    if (resync_) return;
    resync_ = true;
    resync_why_ = why;
    resync_from_ = offset();
  }

  void end_resync(bool at_end) {
    if (!resync_) return;
    resync_ = false;
    if (at_end && std::strcmp(resync_why_, "record_past_end") == 0) {
      report_.truncated = true;
      report_.note("log.bin ends inside a record at byte " + std::to_string(resync_from_));
      return;
    }
    report_.count(resync_why_);
    ++report_.skipped;
    report_.note(std::string(resync_why_) + ": log.bin bytes " + std::to_string(resync_from_) + " to " +
                 std::to_string(offset()) + " skipped");
  }

  // After damage: a record stamped within a day of the recording.
  bool plausible_time(std::uint32_t ts) const {
    const std::int64_t rel = static_cast<std::int64_t>(ts) - start_u32_;
    return rel >= -86400 && rel <= bound_secs_ + 86400;
  }

  Report& report_;
  ByteSource* data_ = nullptr;
  WindowSource* window_ = nullptr;  // the data entry's stored bytes
  std::uint32_t start_u32_ = 0;
  std::int64_t bound_secs_ = 0;
  std::vector<unsigned char> buf_;
  std::size_t beg_ = 0, end_ = 0;
  std::int64_t buf_off_ = 0;
  bool eof_ = false, resync_ = false;
  const char* resync_why_ = "";
  std::int64_t resync_from_ = 0;
};

}  // namespace gt3x

class Gt3xDecoder : public Decoder {
 public:
  // `zip` is the .gt3x file; `inflater` reads deflated entries (null: only
  // stored entries can be read). Options: compat (1), impute_zeroes (0).
  Gt3xDecoder(ByteSource& zip, const Options& opts, EntryInflater* inflater = nullptr)
      : zip_(zip, inflater), records_(report_), rules_(ReadRules::of(opts)) {
    impute_ = opts.num("impute_zeroes", 0) != 0;
  }

  bool open() override {
    info_.format = "gt3x";
    info_.has_time = true;
    gt3x::ZipEntries z;
    if (!zip_.find_entries(z, report_, error_)) return false;
    if (!z.info.found) return fail(z.error.empty() ? "no info.txt in the zip" : z.error);
    std::string text;
    if (!zip_.read_small_entry(z.info, text, error_)) return false;
    gt3x::Info info;
    info.parse(text);
    if (!take_info(info)) return false;
    info_.header_text = text;
    const bool use_activity =
        z.activity.found && (old_ || !z.log.found);
    if (!use_activity && !z.log.found) {
      return fail(z.error.empty() ? "no log.bin or activity.bin in the zip" : z.error);
    }
    old_ = use_activity;
    ByteSource* data = nullptr;
    if (!zip_.open_entry(use_activity ? z.activity : z.log, data, error_)) return false;
    gt3x::WindowSource* const window = zip_.last_window();
    if (old_) {
      act_total_ = z.activity.size * 2 / 9;  // 36 bits a sample
      cap_ = -1;  // read.gt3x neither caps nor pads activity.bin
    }
    build_table();
    records_.start(data, window, start_u32_, bound_secs_);
    return true;
  }

  std::int64_t read(SampleBuffer& out, std::int64_t max_units) override {
    std::int64_t units = 0;
    if (!records_.started()) {
      done_ = true;
      return 0;
    }
    for (;;) {
      drain(out);
      if (pending()) break;
      if (input_done_) {
        done_ = true;
        break;
      }
      if ((max_units >= 0 && units >= max_units) || out.full()) break;
      units += old_ ? next_activity_bin_second() : next_log_record();
    }
    report_.units += units;
    return units;
  }

  bool done() const override { return done_; }
  std::size_t max_samples_per_unit() const override { return gt3x::kMaxRate; }

 private:
  struct ZeroRun {
    std::uint32_t ts = 0;     // time stamp the run starts at
    std::int64_t left = 0;    // zeros still to give
    std::int64_t i = 0;       // index of the next zero within the run
  };

  bool fail(const std::string& why) {
    error_ = why;
    return false;
  }

  bool take_info(const gt3x::Info& info) {
    const std::string* rate = info.get("Sample Rate");
    const std::string* start = info.get("Start Date");
    double r = 0;
    if (rate == nullptr || !gt3x::parse_number(*rate, r)) return fail("info.txt has no Sample Rate");
    if (r != std::floor(r) || r < 1 || r > gt3x::kMaxRate) {
      return fail("info.txt's Sample Rate " + *rate + " is not a whole number in 1.." +
                  std::to_string(gt3x::kMaxRate));
    }
    rate_ = static_cast<int>(r);
    inv_rate_ = 1.0 / rate_;
    if (start == nullptr || !gt3x::parse_ticks(*start, start_d_)) {
      return fail("info.txt has no Start Date in .NET ticks");
    }
    start_u32_ = start_d_ >= 0 && start_d_ < 4294967296.0 ? static_cast<std::uint32_t>(start_d_) : 0;
    const std::string* serial = info.get("Serial Number");
    const std::string* dev = info.get("Device Type");
    const std::string* fw = info.get("Firmware");
    info_.serial = serial ? *serial : "";
    info_.device = dev ? *dev : "";
    info_.sf = rate_;
    info_.start_time = start_d_;
    const std::string prefix = info_.serial.substr(0, 3);
    const bool six_g = prefix == "NEO" || prefix == "CLE" || prefix == "MRA";
    old_ = (prefix == "NEO" || prefix == "MRA") && fw != nullptr && gt3x::firmware_at_most_2_5_0(*fw);
    const std::string* sc = info.get("Acceleration Scale");
    if (sc == nullptr || !gt3x::parse_number(*sc, scale_) || !plausible_scale(scale_)) {
      // read.gt3x: 341 for old files and NEO, CLE, MRA; 256 for MOS, TAS
      scale_ = (old_ || six_g || !(prefix == "MOS" || prefix == "TAS")) ? 341.0 : 256.0;
      if (sc != nullptr) report_.note("info.txt's Acceleration Scale '" + *sc + "' unusable: " + std::to_string(scale_));
    }
    double range = 0;
    const std::string* amax = info.get("Acceleration Max");
    info_.range_g = amax && gt3x::parse_number(*amax, range) ? range : (six_g || old_ ? 6.0 : 8.0);
    take_length(info);
    return true;
  }

  // read.gt3x's get_n_samples(): (end - start) * rate samples, end = Last
  // Sample Time, else Stop Date (Download Date when that is 0); 100 days
  // when not positive.
  void take_length(const gt3x::Info& info) {
    double end = std::numeric_limits<double>::quiet_NaN();
    const std::string* last = info.get("Last Sample Time");
    if (last != nullptr) {
      gt3x::parse_ticks(*last, end);
    } else if (const std::string* stop = info.get("Stop Date")) {
      gt3x::parse_ticks(*stop, end);
      const std::string* dl = info.get("Download Date");
      if (end < gt3x::kEpoch0001 + 1 && dl != nullptr) gt3x::parse_ticks(*dl, end);
    }
    const double n = (end - start_d_) * rate_;
    if (!(n > 0)) {
      max_samples_ = static_cast<std::int64_t>(gt3x::kFallbackDays * 86400 * rate_);
      report_.note("info.txt gives no recording end after its start: 100 days assumed");
    } else {
      max_samples_ = static_cast<std::int64_t>(std::min(n, 2147483647.0));
    }
    bound_secs_ = max_samples_ / rate_ + 1;
    cap_ = rules_.compat && impute_ ? max_samples_ : -1;
    expected_ = start_u32_;
  }

  // counts per g: ActiGraph uses 256 and 341; far outside is damage
  static bool plausible_scale(double s) { return std::isfinite(s) && s >= 1 && s <= 1e5; }

  // counts / scale rounded to 3 decimals, for every 16-bit count.
  void build_table() {
    table_.assign(65536, 0.0);
    for (int c = -32768; c < 32768; ++c) {
      table_[static_cast<std::uint16_t>(c)] = std::round((c / scale_) * 1000.0) / 1000.0;
    }
  }

  double time_of(std::uint32_t ts, std::int64_t i) const {
    if (rules_.compat) {
      const double idx = (static_cast<double>(static_cast<std::uint32_t>(ts - start_u32_)) +
                          static_cast<double>(i) * inv_rate_) * gt3x::kTimeUnit;
      return start_d_ + idx / gt3x::kTimeUnit;
    }
    return static_cast<double>(ts) + static_cast<double>(i) / rate_;
  }
  double time_of_old(std::int64_t i) const {
    if (rules_.compat) return start_d_ + (static_cast<double>(i) * inv_rate_ * gt3x::kTimeUnit) / gt3x::kTimeUnit;
    return start_d_ + static_cast<double>(i) / rate_;
  }

  bool pending() const { return runs_n_ > 0 || cur_i_ < cur_n_; }

  // Gives pending zeros, then the pending second, as far as out has room.
  void drain(SampleBuffer& out) {
    while (runs_n_ > 0 && !out.full()) {
      ZeroRun& r = runs_[0];
      const std::int64_t k = std::min<std::int64_t>(r.left, static_cast<std::int64_t>(out.room()));
      for (std::int64_t j = 0; j < k; ++j) {
        const std::size_t n = out.n + static_cast<std::size_t>(j);
        out.x[n] = out.y[n] = out.z[n] = 0.0;
        if (out.t) out.t[n] = std::numeric_limits<double>::quiet_NaN();
        if (out.time) out.time[n] = time_of(r.ts, r.i + j);
      }
      out.n += static_cast<std::size_t>(k);
      report_.samples += k;
      r.i += k;
      r.left -= k;
      if (r.left == 0) {
        runs_[0] = runs_[1];
        runs_[1] = runs_[2];
        --runs_n_;
      }
    }
    if (cur_i_ < cur_n_ && !out.full()) {
      const int k = static_cast<int>(std::min<std::size_t>(static_cast<std::size_t>(cur_n_ - cur_i_), out.room()));
      const std::size_t n0 = out.n;
      std::memcpy(out.x + n0, cx_ + cur_i_, sizeof(double) * static_cast<std::size_t>(k));
      std::memcpy(out.y + n0, cy_ + cur_i_, sizeof(double) * static_cast<std::size_t>(k));
      std::memcpy(out.z + n0, cz_ + cur_i_, sizeof(double) * static_cast<std::size_t>(k));
      if (out.t) std::fill(out.t + n0, out.t + n0 + k, std::numeric_limits<double>::quiet_NaN());
      if (out.time) {
        for (int j = 0; j < k; ++j) {
          out.time[n0 + static_cast<std::size_t>(j)] =
              old_ ? time_of_old(cur_first_ + cur_i_ + j) : time_of(cur_ts_, cur_i_ + j);
        }
      }
      out.n += static_cast<std::size_t>(k);
      cur_i_ += k;
      report_.samples += k;
    }
  }

  void add_zeros(std::uint32_t ts, std::int64_t n) {
    if (cap_ >= 0) n = std::min(n, cap_ - produced_);
    if (n <= 0) return;
    runs_[runs_n_++] = ZeroRun{ts, n, 0};
    produced_ += n;
  }

  // End of the input (or of what info.txt allows): read.gt3x pads a whole
  // imputed read with zeros to max_samples.
  void finish() {
    input_done_ = true;
    if (cap_ >= 0 && !compat_pad_done_ && !report_.read_error) add_zeros(expected_, cap_ - produced_);
    compat_pad_done_ = true;
  }

  // ---- log.bin

  // Reads records until one gives a second of samples (returns 1) or zeros
  // are pending or the input ends (returns 0).
  std::int64_t next_log_record() {
    while (!pending() && !input_done_) {
      if (!records_.next_record()) {
        finish();
        return 0;
      }
      const unsigned char* p = records_.here();
      const std::size_t size = le16(p + 6);
      const std::int64_t at = records_.offset();
      records_.advance(gt3x::kHeaderLen + size + 1);
      if (p[1] == gt3x::kParameters) take_parameters(p + gt3x::kHeaderLen, size);
      if (p[1] == gt3x::kActivity || p[1] == gt3x::kActivity2) {
        if (activity(p[1], le32(p + 2), p + gt3x::kHeaderLen, size, at)) return 1;
      }
    }
    return 0;
  }

  void take_parameters(const unsigned char* q, std::size_t size) {
    for (std::size_t i = 0; i + 8 <= size; i += 8) {
      const std::uint16_t addr = le16(q + i), key = le16(q + i + 2);
      const std::uint32_t v = le32(q + i + 4);
      if (addr == gt3x::kAddrConfig && key == gt3x::kKeyStartTime) expected_ = v;
      if (addr == gt3x::kAddrDevice && key == gt3x::kKeyAccelScale && !rules_.compat) {
        const double s = gt3x::decode_param_float(v);
        if (plausible_scale(s) && s != scale_) {
          scale_ = s;
          build_table();
        }
      }
    }
  }

  // A stamp outside the recording is skipped (false); a jump forward that
  // the next record does not follow (it goes back between the expected time
  // and this stamp) is a damaged stamp, taken as the expected time.
  bool check_time(std::uint32_t& ts, std::int64_t at) {
    const std::int64_t rel = static_cast<std::int64_t>(ts) - start_u32_;
    if (rel > bound_secs_ && !impute_) {  // kept, as read.gt3x's batches keep it
      report_.count("past_last_sample_time");
    } else if (rel < 0 || rel > bound_secs_) {
      report_.count("bad_timestamp");
      ++report_.skipped;
      report_.note("record at log.bin byte " + std::to_string(at) + " stamped " + std::to_string(ts) +
                   ", outside the recording (" + std::to_string(start_u32_) + " + " +
                   std::to_string(bound_secs_) + " s): skipped");
      return false;
    }
    std::uint32_t next = 0;
    if (ts > expected_ && seen_activity_ && records_.peek_activity_time(next) && next >= expected_ && next < ts) {
      report_.count("bad_timestamp");
      report_.note("record at log.bin byte " + std::to_string(at) + " stamped " + std::to_string(ts) +
                   ", the next " + std::to_string(next) + ": taken as " + std::to_string(expected_));
      ts = expected_;
    }
    return true;
  }

  // One ACTIVITY / ACTIVITY2 record; true when it gave samples.
  bool activity(unsigned char type, std::uint32_t ts, const unsigned char* q, std::size_t size,
                std::int64_t at) {
    std::size_t n = type == gt3x::kActivity ? size * 2 / 9 : size / 6;
    if (n > static_cast<std::size_t>(rate_)) {
      report_.count("long_records");  // read.gt3x keeps the first sf samples
      n = static_cast<std::size_t>(rate_);
    }
    unpack(type, q, n);  // before check_time(), whose look ahead may move the buffer
    if (!check_time(ts, at)) return false;
    if (cap_ >= 0 && static_cast<std::int64_t>(n) + produced_ > cap_) return stop_at_cap(at);
    if (ts > expected_) {
      const std::int64_t gap = static_cast<std::int64_t>(ts) - expected_;
      ++report_.gaps;
      report_.gap_seconds += static_cast<double>(gap);
      if (impute_) add_zeros(expected_, gap * rate_);
    } else if (ts < expected_ && seen_activity_) {
      report_.count("time_backwards");
      report_.note("record at log.bin byte " + std::to_string(at) + " stamped " +
                   std::to_string(expected_ - ts) + " s before the previous one");
    }
    seen_activity_ = true;
    if (cap_ >= 0 && static_cast<std::int64_t>(n) + produced_ > cap_) return stop_at_cap(at);
    expected_ = ts + 1;
    if (n == 0) {  // idle sleep: no samples this second
      report_.count("idle_seconds");
      if (impute_) add_zeros(ts, rate_);
      return false;
    }
    cur_ts_ = ts;
    cur_n_ = static_cast<int>(n);
    cur_i_ = 0;
    produced_ += static_cast<std::int64_t>(n);
    return true;
  }

  bool stop_at_cap(std::int64_t at) {
    report_.count("after_last_sample_time");
    report_.note("info.txt's Last Sample Time reached (" + std::to_string(cap_) +
                 " samples) at log.bin byte " + std::to_string(at) + ": the rest is not read (compat = 1)");
    finish();
    return false;
  }

  void unpack(unsigned char type, const unsigned char* q, std::size_t n) {
    const double* t = table_.data();
    if (type == gt3x::kActivity2) {  // little-endian int16, XYZ
      for (std::size_t i = 0; i < n; ++i, q += 6) {
        cx_[i] = t[le16(q)];
        cy_[i] = t[le16(q + 2)];
        cz_[i] = t[le16(q + 4)];
      }
      return;
    }
    for (std::size_t i = 0; i < n; ++i) {  // 12-bit, YXZ
      cy_[i] = t[static_cast<std::uint16_t>(gt3x::unpack12(q, 9 * i))];
      cx_[i] = t[static_cast<std::uint16_t>(gt3x::unpack12(q, 9 * i + 3))];
      cz_[i] = t[static_cast<std::uint16_t>(gt3x::unpack12(q, 9 * i + 6))];
    }
  }

  // ---- activity.bin: a packed 12-bit YXZ stream, floor(bytes * 2 / 9)
  // samples, timed from info.txt's start (NHANES-GT3X-File-Format).
  std::int64_t next_activity_bin_second() {
    const std::int64_t n = std::min<std::int64_t>(rate_, act_total_ - act_i_);
    if (n <= 0) {
      finish();
      return 0;
    }
    const std::size_t nib = static_cast<std::size_t>(act_i_ & 1);  // odd samples start mid-byte
    const std::size_t nibs = nib + 9 * static_cast<std::size_t>(n);
    if (!records_.ensure((nibs + 1) / 2)) {
      const std::size_t have = records_.buffered() * 2;  // nibbles left
      const std::int64_t whole = static_cast<std::int64_t>(have > nib ? (have - nib) / 9 : 0);
      report_.truncated = true;
      report_.note("activity.bin ends at byte " + std::to_string(records_.buffered_end()) +
                   ", " + std::to_string(act_total_ - act_i_ - whole) + " samples short of its size");
      act_total_ = act_i_ + whole;
      return next_activity_bin_second();
    }
    const double* t = table_.data();
    const unsigned char* q = records_.here();
    for (std::int64_t i = 0; i < n; ++i) {
      const std::size_t k = nib + 9 * static_cast<std::size_t>(i);
      cy_[i] = t[static_cast<std::uint16_t>(gt3x::unpack12(q, k))];
      cx_[i] = t[static_cast<std::uint16_t>(gt3x::unpack12(q, k + 3))];
      cz_[i] = t[static_cast<std::uint16_t>(gt3x::unpack12(q, k + 6))];
    }
    records_.advance(nibs / 2);
    cur_first_ = act_i_;
    cur_n_ = static_cast<int>(n);
    cur_i_ = 0;
    act_i_ += n;
    return 1;
  }

  gt3x::ZipReader zip_;
  gt3x::RecordStream records_;  // the data entry's bytes and records
  // the reading rules (compat, interpolation, resample_fused), read once
  const ReadRules rules_;
  bool impute_ = false, old_ = false;
  // from info.txt
  int rate_ = 1;
  double inv_rate_ = 1.0, scale_ = 256.0, start_d_ = 0.0;
  std::uint32_t start_u32_ = 0;
  std::int64_t max_samples_ = 0, bound_secs_ = 0, cap_ = -1, act_total_ = 0, act_i_ = 0;
  std::vector<double> table_;
  // stream state
  std::uint32_t expected_ = 0;
  bool seen_activity_ = false, input_done_ = false, done_ = false, compat_pad_done_ = false;
  std::int64_t produced_ = 0;
  ZeroRun runs_[3];
  int runs_n_ = 0;
  double cx_[gt3x::kMaxRate], cy_[gt3x::kMaxRate], cz_[gt3x::kMaxRate];
  std::uint32_t cur_ts_ = 0;
  std::int64_t cur_first_ = 0;
  int cur_n_ = 0, cur_i_ = 0;
};

}  // namespace gravcal

#endif  // GRAVCAL_DECODE_GT3X_HPP
