// libFuzzer harness: the Parmay Matrix decoder on arbitrary bytes. The first
// byte picks compat (bit 1), the interpolation (bit 3), the block size
// (max_units) and the buffer; bit 0 puts a valid file header before the
// rest and bit 6 rewrites the CRC-32 of every packet found, so that the
// fuzzer reaches the samples of packets that pass their check. Checks: no
// crash, no write past the buffer, progress on every call, finite times
// (and finite acceleration in gravcal's own reading, compat = 0), report
// counts consistent with what was given, nothing after the end, a packet
// table of one row a packet (unit_log()); and the
// same samples, bit for bit, and the same counts from the decoder's
// point-by-point path alone (option run_loop = 0, one big buffer, no block
// limit): the grid's fast loop must not change a bit. A packet's
// header times can ask for any length of grid (GGIRread's resampling), so
// the harness stops after kMaxSamples samples.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/decoders/decode_parmay.hpp"

#define CHECK(cond)                                                              \
  do {                                                                           \
    if (!(cond)) {                                                               \
      std::fprintf(stderr, "invariant failed, line %d: %s\n", __LINE__, #cond); \
      __builtin_trap();                                                          \
    }                                                                            \
  } while (0)

static const std::int64_t kMaxSamples = 200000;

// What a decoding gave: every sample's five values, and the report.
struct Decoded {
  std::vector<double> v;  // x, y, z, temperature, time of each sample
  bool opened = false, capped = false;
  std::int64_t skipped = 0, gaps = 0;
  std::vector<std::pair<std::string, std::int64_t>> counts;
};

static Decoded decode_all(const std::vector<unsigned char>& bytes, std::uint8_t mode, bool run_loop) {
  Decoded res;
  gravcal::MemorySource src(bytes.data(), bytes.size());
  gravcal::Options opts;
  const bool compat = (mode & 2) == 0;
  opts.set("compat", compat ? 1.0 : 0.0);
  opts.set("interpolation", (mode & 8) ? 2.0 : 1.0);
  opts.set("resample_fused", (mode & 128) ? 1.0 : 0.0);
  opts.set("run_loop", run_loop ? 1.0 : 0.0);
  gravcal::ParmayDecoder dec(src, opts);
  if (!dec.open()) {
    CHECK(!dec.error().empty());
    return res;
  }
  res.opened = true;
  // the packet table (GGIR's QClog of the packets, built in R): a column
  // each, one value a packet, counts not negative, checksums 0 or 1 (all 1
  // where damaged packets are skipped)
  const gravcal::Decoder::UnitLog log = dec.unit_log();
  CHECK(log.names.size() == 4 && log.columns.size() == 4);
  for (const auto& c : log.columns) CHECK(c.size() == log.columns[0].size() && !c.empty());
  for (std::size_t i = 0; i < log.columns[0].size(); ++i) {
    CHECK(log.columns[2][i] >= 0);
    CHECK(log.columns[3][i] == 1 || (compat && log.columns[3][i] == 0));
  }
  CHECK(dec.info().sf == 12.5 || dec.info().sf == 25 || dec.info().sf == 50 ||
        dec.info().sf == 100);
  const std::int64_t max_units = !run_loop || (mode & 4) ? -1 : 1 + ((mode >> 4) & 1);
  const std::size_t cap = run_loop && (mode & 32) ? 7 : 600;
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap);
  std::int64_t samples = 0, units = 0;
  bool capped = false;
  while (!dec.done()) {
    gravcal::SampleBuffer out;
    out.x = x.data();
    out.y = y.data();
    out.z = z.data();
    out.t = t.data();
    out.time = tm.data();
    out.capacity = cap;
    const std::int64_t u = dec.read(out, max_units);
    CHECK(out.n <= cap && u >= 0);
    CHECK(!(u == 0 && out.n == 0 && !dec.done()));  // no progress
    for (std::size_t i = 0; i < out.n; ++i) {
      CHECK(std::isfinite(tm[i]));
      if (!compat) CHECK(std::isfinite(x[i]) && std::isfinite(y[i]) && std::isfinite(z[i]));
    }
    for (std::size_t i = 0; i < out.n; ++i) {
      for (const double* c : {x.data(), y.data(), z.data(), t.data(), tm.data()}) res.v.push_back(c[i]);
    }
    samples += static_cast<std::int64_t>(out.n);
    units += u;
    if (samples > kMaxSamples) {
      capped = true;
      break;
    }
  }
  const gravcal::Report& r = dec.report();
  CHECK(r.samples == samples);
  CHECK(r.notes.size() <= gravcal::Report::max_notes);
  CHECK(r.gaps >= 0 && r.gap_seconds >= 0);
  res.capped = capped;
  res.skipped = r.skipped;
  res.gaps = r.gaps;
  res.counts = r.counters;
  if (capped) return res;
  CHECK(r.units == units);
  gravcal::SampleBuffer out;
  out.x = x.data();
  out.y = y.data();
  out.z = z.data();
  out.capacity = cap;
  CHECK(dec.read(out, -1) == 0 && out.n == 0);
  return res;
}

static void fix_crcs(std::vector<unsigned char>& b) {
  static const char pat[] = "MDTCPACK";
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i + 8 <= b.size(); ++i) {
    if (std::memcmp(b.data() + i, pat, 8) == 0) at.push_back(i);
  }
  for (std::size_t k = 0; k < at.size(); ++k) {
    const std::size_t from = at[k] + 12;
    const std::size_t to = k + 1 < at.size() ? at[k + 1] : b.size();
    if (from > to || at[k] + 12 > b.size()) continue;
    const std::uint32_t c = gravcal::Crc32::update(0, b.data() + from, to - from);
    for (int i = 0; i < 4; ++i) b[at[k] + 8 + i] = static_cast<unsigned char>(c >> (8 * i));
  }
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const std::uint8_t mode = in.byte();
  std::vector<unsigned char> bytes;
  if (mode & 1) {
    bytes.assign(524, 0);
    std::memcpy(bytes.data() + 512, "MDTC", 4);
    bytes[516] = 4;  // packets
    bytes[520] = 8;  // +-8 g
  }
  bytes.insert(bytes.end(), in.p, in.p + in.n);
  if (mode & 64) fix_crcs(bytes);
  const Decoded a = decode_all(bytes, mode, true);
  const Decoded b = decode_all(bytes, mode, false);
  CHECK(a.opened == b.opened);
  if (a.opened && !a.capped && !b.capped) {
    CHECK(a.v.size() == b.v.size());
    CHECK(a.v.empty() || std::memcmp(a.v.data(), b.v.data(), a.v.size() * sizeof(double)) == 0);
    CHECK(a.skipped == b.skipped && a.gaps == b.gaps && a.counts == b.counts);
  }
  return 0;
}
