// libFuzzer harness: the GENEActiv decoder on arbitrary bytes. The first
// byte picks compat, the block size (max_units) and the buffer; when its low
// bit is set a valid header goes before the rest, so the fuzzer works on
// pages. Checks: no crash, no call past the buffer, progress on every call,
// finite values, report counts consistent with what was given, and the
// same bits with and without the AVX2 paths.
#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include <cstdio>

#include "fuzz_input.hpp"
#include "gravcal/decoders/decode_geneactiv.hpp"

// Stops with the line of the broken invariant.
#define CHECK(cond)                                             \
  do {                                                          \
    if (!(cond)) {                                              \
      std::fprintf(stderr, "invariant failed, line %d: %s\n", __LINE__, #cond); \
      __builtin_trap();                                         \
    }                                                           \
  } while (0)

static const char kHeader[] =
    "Device Identity\r\nDevice Unique Serial Code:012967\r\nDevice Type:GENEActiv\r\n"
    "Device Model:1.1\r\nAccelerometer Range:-8 to 8\r\nConfiguration Info\r\n"
    "Measurement Frequency:85.7 Hz\r\nTime Zone:GMT +01:00\r\nCalibration Data\r\n"
    "x gain:25875\r\nx offset:439\r\ny gain:25734\r\ny offset:-662\r\nz gain:25538\r\n"
    "z offset:-3056\r\nVolts:300\r\nLux:800\r\n\r\nMemory Status\r\nNumber of Pages:2\r\n\r\n";

// Decodes `bytes` (mode as below), checks the invariants and returns a
// digest of every sample, time and temperature and of the report's counts.
static std::uint64_t decode_all(const std::vector<unsigned char>& bytes, std::uint8_t mode) {
  gravcal::MemorySource src(bytes.data(), bytes.size());
  gravcal::Options opts;
  opts.set("compat", (mode & 2) ? 0.0 : 1.0);
  gravcal::GeneactivDecoder dec(src, opts);
  if (!dec.open()) {
    CHECK(!(dec.error().empty()));
    return 0;
  }
  std::uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* p, std::size_t n) {
    const unsigned char* b = static_cast<const unsigned char*>(p);
    for (std::size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  const std::int64_t max_units = (mode & 4) ? -1 : 1 + ((mode >> 3) & 3);
  const std::size_t cap = (mode & 32) ? 7 : 600;
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap), li(cap);
  std::int64_t samples = 0, units = 0;
  for (int calls = 0; !dec.done(); ++calls) {
    gravcal::SampleBuffer out;
    out.x = x.data();
    out.y = y.data();
    out.z = z.data();
    out.t = t.data();
    out.time = tm.data();
    out.light = (mode & 64) ? li.data() : nullptr;  // light asked or not
    out.capacity = cap;
    const std::int64_t u = dec.read(out, max_units);
    CHECK(!(out.n > cap || u < 0 || (max_units >= 0 && u > max_units)));
    CHECK(!(u == 0 && out.n == 0 && !dec.done()));  // no progress
    // compat 1: a time that is not finite only where a page's rate or the
    // start is one the reference's times are not defined by (NaN: 0 Hz, a
    // start not read) or infinite for (a block ending at 0 Hz)
    const gravcal::Report& now = dec.report();
    const bool odd_times = (mode & 2) == 0 &&
                           (now.get("ggir_time_undefined") > 0 || now.get("ggir_start_unread") > 0 ||
                            now.get("rate_changes") > 0 || now.get("ggir_rate_mismatch") > 0);
    for (std::size_t i = 0; i < out.n; ++i) {
      CHECK(std::isfinite(x[i]) && std::isfinite(y[i]) && std::isfinite(z[i]) &&
            std::isfinite(t[i]) && (std::isfinite(tm[i]) || odd_times));
      const double v[5] = {x[i], y[i], z[i], t[i], tm[i]};
      mix(v, sizeof v);
    }
    samples += static_cast<std::int64_t>(out.n);
    units += u;
    mix(&u, sizeof u);
    CHECK(!(calls > 10000000));
  }
  const gravcal::Report& r = dec.report();
  CHECK(!(r.samples != samples));
  CHECK(!(r.units + r.skipped != units));
  // (compat 1: a damaged page may give more, as the reference reads it)
  const std::size_t per_page = (mode & 2) ? gravcal::geneactiv::kSamplesPerPage
                                          : gravcal::geneactiv::kMaxPageSamples;
  CHECK(!(r.samples > r.units * static_cast<std::int64_t>(per_page)));
  CHECK(!(r.gaps < 0 || !(r.gap_seconds >= 0) || !std::isfinite(r.gap_seconds)));
  CHECK(!(r.notes.size() > gravcal::Report::max_notes));
  for (const auto& c : r.counters) mix(&c.second, sizeof c.second);
  // a further read gives nothing
  gravcal::SampleBuffer out;
  out.x = x.data();
  out.y = y.data();
  out.z = z.data();
  out.capacity = cap;
  CHECK(!(dec.read(out, -1) != 0 || out.n != 0));
  return h;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const std::uint8_t mode = in.byte();
  std::vector<unsigned char> bytes;
  if (mode & 1) bytes.assign(kHeader, kHeader + sizeof kHeader - 1);
  bytes.insert(bytes.end(), in.p, in.p + in.n);
  const std::uint64_t h = decode_all(bytes, mode);
  // light asked or not (mode bit 64): the other columns are the same
  CHECK(decode_all(bytes, mode ^ 64) == h);
  // the baseline paths (no AVX2: gravcal/kernels/simd.hpp) give the same bits
  if (gravcal::use_avx2()) {
    gravcal::set_avx2(false);
    const std::uint64_t b = decode_all(bytes, mode);
    gravcal::set_avx2(true);
    CHECK(b == h);
  }
  return 0;
}
