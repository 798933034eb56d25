// libFuzzer harness: the .cwa decoder on arbitrary bytes, in both modes.
// The first 3 bytes choose the mode (bit 0: compat; bit 2: nearest-neighbour
// interpolation, GGIR's interpolationType = 2), the window size and whether to make the
// blocks' checksums (and "MD"/"AX" tags) right, so that fuzzed content gets
// past the checksum. Checks, besides the sanitizers' findings: no read past
// the buffer's capacity, the report's counts agree with what was given, the
// decoder always makes progress, and the samples are the same, to the bit,
// whether pulled through a large buffer or a 7-sample one, and with or
// without the AVX2 paths; readAxivity's log (compat: unit_log()) holds rows
// of its three kinds only, the same whatever the buffer, none without
// compat.
#include <cstring>
#include <string>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/decoders/decode_cwa.hpp"

namespace {

constexpr std::size_t max_out = 20000;  // enough; a fuzzed gap may impute far more

struct Run {
  std::vector<double> v;  // x, y, z, t, time of each sample
  std::int64_t units = 0;
  gravcal::Report report;
  gravcal::Decoder::UnitLog log;
  bool done = false;
};

bool run(const std::vector<unsigned char>& file, bool compat, std::int64_t window,
         std::size_t cap, Run& r, double interpolation = 1, bool zone = false) {
  gravcal::MemorySource src(file.data(), file.size());
  gravcal::Options opts;
  opts.set("compat", compat ? 1.0 : 0.0);
  opts.set("interpolation", interpolation);
  if (zone) {
    // a zone whose offset changes every year from 2000 (as R/zone.R gives
    // them), each change's hour marked: block times that jump back and forth
    opts.set("tz_n", 129.0);
    opts.set("tz_amb_n", 64.0);
    for (int i = 0; i < 129; ++i) {
      const double at = 946684800.0 + (i == 0 ? 0 : (i - 1) * 15778800.0 + 7200);
      opts.set("tz_at_" + std::to_string(i), at);
      opts.set("tz_off_" + std::to_string(i), (i % 2) ? 3600.0 : 0.0);
      if (i % 2 == 0 && i > 0) {
        opts.set("tz_amb_lo_" + std::to_string(i / 2 - 1), at - 3600);
        opts.set("tz_amb_hi_" + std::to_string(i / 2 - 1), at);
      }
    }
  }
  gravcal::CwaDecoder dec(src, opts);
  if (!dec.open()) {
    if (dec.error().empty()) __builtin_trap();
    return false;
  }
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap), li(cap);
  int idle = 0;
  while (!dec.done() && r.v.size() / 5 < max_out) {
    gravcal::SampleBuffer out;
    out.x = x.data();
    out.y = y.data();
    out.z = z.data();
    out.t = t.data();
    out.time = tm.data();
    out.light = li.data();
    out.capacity = cap;
    const std::int64_t u = dec.read(out, window);
    if (out.n > cap || u < 0) __builtin_trap();
    if (!compat && window >= 0 && u > window) __builtin_trap();
    r.units += u;
    for (std::size_t i = 0; i < out.n; ++i) {
      // light: a block's 10-bit value
      if (!(li[i] >= 0 && li[i] <= 1023 && li[i] == static_cast<int>(li[i]))) __builtin_trap();
      const double s[5] = {x[i], y[i], z[i], t[i], tm[i]};
      r.v.insert(r.v.end(), s, s + 5);
    }
    idle = (out.n == 0 && u == 0) ? idle + 1 : 0;
    if (idle > 2) __builtin_trap();  // no progress and not done
  }
  r.report = dec.report();
  r.log = dec.unit_log();
  r.done = dec.done();
  return true;
}

void check(const Run& r, bool compat, std::size_t blocks) {
  const gravcal::Report& rep = r.report;
  if (rep.samples != static_cast<std::int64_t>(r.v.size() / 5)) __builtin_trap();
  if (rep.units < 0 || rep.skipped < 0 || rep.gaps < 0 || !(rep.gap_seconds >= 0)) __builtin_trap();
  if (static_cast<std::size_t>(rep.units + rep.skipped) > blocks) __builtin_trap();
  if (!compat && rep.samples > 120 * rep.units) __builtin_trap();
  const std::vector<std::vector<double>>& c = r.log.columns;
  if (!compat && !c.empty() && !c[0].empty()) __builtin_trap();
  for (std::size_t k = 0; !c.empty() && k < c[0].size(); ++k) {
    const double kind = c[0][k], pass = c[1][k], imputed = c[9][k];
    if (!(kind == 0 || kind == 1 || kind == 2)) __builtin_trap();
    if ((kind == 2) != (pass == 1) || !(imputed == 0 || imputed == 1)) __builtin_trap();
    if (kind < 2 && (imputed != 0 || c[3][k] != c[2][k] + 1)) __builtin_trap();
  }
}

bool same(const Run& a, const Run& b) {
  const std::size_t n = std::min(a.v.size(), b.v.size());
  return n == 0 || std::memcmp(a.v.data(), b.v.data(), n * sizeof(double)) == 0;
}

// Makes every whole data block's checksum (and optionally its tag) right.
void repair(std::vector<unsigned char>& f, bool tags) {
  if (tags && f.size() >= 2) f[0] = 'M', f[1] = 'D';
  for (std::size_t at = 1024; at + 512 <= f.size(); at += 512) {
    if (tags) f[at] = 'A', f[at + 1] = 'X', f[at + 2] = 0xfc, f[at + 3] = 0x01;
    unsigned sum = 0;
    for (std::size_t i = 0; i < 510; i += 2) sum += gravcal::le16(&f[at + i]);
    const unsigned c = (0x10000u - (sum & 0xffffu)) & 0xffffu;
    f[at + 510] = static_cast<unsigned char>(c & 0xff);
    f[at + 511] = static_cast<unsigned char>(c >> 8);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const std::uint8_t mode = in.byte();
  const std::int64_t window = static_cast<std::int64_t>(in.byte() % 50) - 1;  // -1: all
  const std::uint8_t fix = in.byte();
  std::vector<unsigned char> file(in.p, in.p + in.n);
  if (fix & 1) repair(file, (fix & 2) != 0);
  const bool compat = mode & 1;
  const double interpolation = (mode & 4) ? 2 : 1;
  const bool zone = (mode & 8) != 0;
  if (window == 0) return 0;
  const std::size_t blocks = file.size() > 1024 ? (file.size() - 1024) / 512 : 0;
  Run big, small;
  const std::size_t cap = 4096;
  const bool ok = run(file, compat, window, cap, big, interpolation, zone);
  if (run(file, compat, window, 7, small, interpolation, zone) != ok) __builtin_trap();
  // the baseline paths (no AVX2: gravcal/kernels/simd.hpp) give the same bits
  if (gravcal::use_avx2()) {
    Run base;
    gravcal::set_avx2(false);
    const bool ok2 = run(file, compat, window, cap, base, interpolation, zone);
    gravcal::set_avx2(true);
    if (ok2 != ok || base.v.size() != big.v.size() || base.units != big.units ||
        base.report.skipped != big.report.skipped || !same(big, base)) {
      __builtin_trap();
    }
  }
  if (!ok) return 0;
  check(big, compat, blocks);
  check(small, compat, blocks);
  if (!same(big, small)) __builtin_trap();
  if (big.done && small.done && big.log.columns != small.log.columns) __builtin_trap();
  return 0;
}
