// libFuzzer harness: arbitrary bytes as an ad hoc csv of time stamp, x, y, z
// (and temperature) through the csv decoder and GGIR's gap imputation of
// rmc.check4timegaps (GgirTimegapsOf<CsvDecoder>), then, for some inputs,
// GGIR's block resampling after it (rmc.doresample), in GGIR-compatible mode.
// The first byte chooses the rate, the time (UNIX seconds, milliseconds, or
// text read by a strptime() format), the resampling, the block (lines per
// reader call) and buffer sizes. Checks: no crash, n <= capacity, units
// within their limit, progress on every read until done, the report's
// samples those given, no zero sample (x = y = z = 0) given, and within a
// block no step of k = max(0.25, 2 / sf) s or more left unfilled after a
// sample whose copies would fit (steps backwards and beyond the fill limit
// excepted, and the step right after a step backwards: GGIR's times slip
// after a single sample between two gaps, two of them put back in). When the last byte's high bit is set (and no resampling),
// g.getmeta()'s mode instead: the previous block carried, a 1-minute limit
// beyond which gaps are imputed as whole epochs (checked: each reported at
// a sample given, with more than one epoch left), times of day read in a
// zone whose offset changes. With a temperature column and the last byte's
// bit 6 set, a wear column after it (rmc.col.wear): every flag given is 1,
// 0 or NaN, and a resampled block asks for none (its decoder has none).
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "gravcal/decoders/decode_csv.hpp"
#include "gravcal/decoders/decode_ggir_resample.hpp"
#include "gravcal/decoders/decode_ggir_timegaps.hpp"

using Gaps = gravcal::GgirTimegapsOf<gravcal::CsvDecoder, long double>;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t mode = data[0];
  gravcal::MemorySource src(data + 1, size - 1);
  gravcal::Options o;
  o.set("compat", 1.0);
  const double sf = (mode & 1) ? 12.5 : 10.0;
  o.set("sf", sf);
  o.set("skip", 0.0);
  o.set("col_time", 1.0);
  if ((mode & 6) == 6) {
    o.set("time_format", std::string("%d/%m/%Y %H:%M:%OS"));
    o.set("time_utc_offset", 3600.0);
    if (mode & 16) {
      // a zone whose offset changes (R/zone.R's table): 2023's two changes
      // in Europe/Amsterdam, the autumn hour marked, blocks of 50 lines
      o.set("tz_n", 3.0);
      o.set("tz_at_0", 946684800.0);
      o.set("tz_off_0", 3600.0);
      o.set("tz_at_1", 1679796000.0);
      o.set("tz_off_1", 7200.0);
      o.set("tz_at_2", 1698548400.0);
      o.set("tz_off_2", 3600.0);
      o.set("tz_amb_n", 1.0);
      o.set("tz_amb_lo_0", 1698544800.0);
      o.set("tz_amb_hi_0", 1698548400.0);
      o.set("block_lines", 50.0);
    }
  } else {
    o.set("time_div", (mode & 2) ? 1000.0 : 1.0);
  }
  o.set("col_x", 2.0);
  o.set("col_y", 3.0);
  o.set("col_z", 4.0);
  if (mode & 4) o.set("col_temp", 5.0);
  const bool wear = (mode & 4) && (data[size - 1] & 0x40) != 0;
  if (wear) o.set("col_wear", 6.0);
  o.set("buffer", 64.0 + 61.0 * (mode >> 5));
  std::unique_ptr<gravcal::CsvDecoder> csv(new gravcal::CsvDecoder(src, o, "adhoc_csv"));
  const bool resample = (mode & 8) != 0;
  const bool epochs = !resample && (data[size - 1] & 0x80) != 0;
  gravcal::GgirTimegapsMode gm;
  if (epochs) {
    gm.carry = true;
    gm.limit_minutes = 1;
    gm.epoch_gaps = true;
    gm.short_epoch = 5;
    gm.long_epoch = (mode & 32) ? 60 : 900;
    gm.local = {0, 3600, 1679792400, 7200, 1698541200, 3600};
  }
  std::unique_ptr<Gaps> gaps(new Gaps(std::move(csv), sf, gm));
  std::unique_ptr<gravcal::Decoder> dec;
  if (resample) {
    dec.reset(new gravcal::GgirResamplerOf<Gaps>(std::move(gaps), sf, (mode & 16) ? 2 : 1, true));
  } else {
    dec.reset(gaps.release());
  }
  if (!dec->open()) return 0;
  if (dec->info().has_wear != (wear && !resample)) __builtin_trap();
  const std::size_t cap = 1 + (mode >> 3);  // 1 .. 32
  std::vector<double> x(cap), y(cap), z(cap), t(cap), tm(cap), w(cap, 0.5);
  const std::int64_t max_units = (mode & 0x40) ? -1 : 1 + (mode >> 5) * 3;
  const double k = std::fmax(0.25, 2 / sf);
  std::int64_t given = 0;
  double last = std::nan("");
  bool back = false;  // the step before went backwards
  for (int calls = 0; calls < 50000 && !dec->done() && given < 200000; ++calls) {
    gravcal::SampleBuffer b;
    b.x = x.data(); b.y = y.data(); b.z = z.data(); b.t = t.data(); b.time = tm.data();
    if (dec->info().has_wear) b.wear = w.data();
    b.capacity = cap;
    const std::int64_t u = dec->read(b, max_units);
    if (b.n > cap) __builtin_trap();
    if (u < 0 || (max_units >= 0 && u > max_units)) __builtin_trap();
    if (u == 0 && b.n == 0 && !dec->done()) __builtin_trap();  // no progress
    for (std::size_t i = 0; i < b.n; ++i) {
      if (!resample && x[i] == 0 && y[i] == 0 && z[i] == 0) __builtin_trap();
      if (b.wear != nullptr && !(w[i] == 0 || w[i] == 1 || std::isnan(w[i]))) __builtin_trap();
      const double step = tm[i] - last;
      // a filled gap leaves steps of 1 / sf; one of k or more only where its
      // fill would pass the limit (1e8 samples) or the times are not finite
      if (!resample && !epochs && !back && std::isfinite(step) && step >= k && step * sf <= 1e7 &&
          std::fabs(last) < 1e12 && std::fabs(tm[i]) < 1e12) {
        __builtin_trap();
      }
      back = step < 0;
      last = tm[i];
    }
    if (u > 0) {
      last = std::nan("");  // a block ended: its gap to the next stays
      back = false;
    }
    given += static_cast<std::int64_t>(b.n);
    for (const auto& g : dec->take_epoch_gaps()) {
      // reported when queued, so at most one block of runs ahead of `given`
      if (!epochs || g.row < 0 || !(g.remaining > 1) || !std::isfinite(g.remaining)) __builtin_trap();
    }
  }
  if (given < 1000000 && dec->done() && dec->report().samples != given) __builtin_trap();
  return 0;
}
