// libFuzzer harness: GGIR's block rules (ggir_blocks.hpp) in front of the
// segmenter, fed arbitrary values in blocks of arbitrary sizes. Checks,
// besides the sanitizers' findings: the windows and what each block reports
// are the same, to the bit, whether a block's samples are pushed at once,
// pushed in the fuzzer's chunks, or written into the rules' own buffer a
// few at a time (space() and commit(), as a decoder does); the counts add
// up; a used block is whole hours (also when the hour is one double below
// a whole number of samples). In compatible mode the segmenter may
// give R's sds only where GGIR's rules see them (Segmenter::lazy_r_sd()):
// then, against R's sds everywhere, every other statistic is the same, and
// so are the rest windows (with their sds, to the bit) and the ties GGIR's
// duplicate filter counts between a window and the last one with means.
// And all of it is the same bits without the AVX2 paths (gravcal/kernels/simd.hpp).
#include <cmath>
#include <cstring>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/ggir/ggir_blocks.hpp"

namespace {

struct Out {
  std::vector<gravcal::WindowStats> w;
  std::vector<gravcal::GgirBlockInfo> b;
};

bool same_info(const gravcal::GgirBlockInfo& a, const gravcal::GgirBlockInfo& b) {
  return a.rows == b.rows && a.zeros == b.zeros && a.ld == b.ld && a.used == b.used &&
         a.carried == b.carried &&
         std::memcmp(&a.first_mean, &b.first_mean, sizeof(double)) == 0 &&
         std::memcmp(&a.temp_sd, &b.temp_sd, sizeof(double)) == 0 &&
         a.temp_sd_exact == b.temp_sd_exact;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const std::uint8_t hour_byte = in.byte();
  double per_hour = 1 + hour_byte % 60;
  // one double below a whole number, as 3600 * 33.3 is: GGIR's fractional
  // `use` and the carry R's `:` then takes (GgirBlocks::shift_carry())
  if (hour_byte & 128) per_hour = std::nextafter(per_hour, 0.0);
  const std::int64_t hour = static_cast<std::int64_t>(per_hour + 1.1920928955078125e-07);
  const double L = 1 + in.byte() % 12 + (in.byte() & 1 ? 0.5 : 0.0);
  const bool compat = in.byte() & 1;
  const bool with_t = in.byte() & 1;
  const std::uint8_t lazy_byte = in.byte();
  const bool lazy = compat && (lazy_byte & 1);
  const double max_sd = 0.001 + (lazy_byte >> 1) / 64.0;  // 0.001 to 2
  std::vector<std::size_t> chunks;
  for (int i = 0; i < 6; ++i) chunks.push_back(in.byte() % 50);  // 0: an empty write
  chunks.push_back(1 + in.byte() % 50);  // so that the samples go on
  // blocks of samples: a length byte, then the samples
  std::vector<std::vector<double>> blocks;
  while (!in.empty() && blocks.size() < 8) {
    const std::size_t n = in.byte() * 2u;
    std::vector<double> b;
    double temp = 20 + in.byte() / 16.0;
    for (std::size_t i = 0; i < n && !in.empty(); ++i) {
      const std::uint8_t k = in.byte();
      double v[4] = {in.sample(), in.sample(), in.sample(), temp};
      if (k % 4 == 0) v[0] = v[1] = v[2] = 0.0;  // idle-sleep zeros
      if (k % 7 == 0) temp = in.sample();        // a new temperature run
      v[3] = temp;
      b.insert(b.end(), v, v + 4);
    }
    blocks.push_back(b);
  }
  Out out[5];
  for (int way = 0; way < 5; ++way) {
    if (way == 3 && !lazy) continue;
    // way 4: as way 0 without the AVX2 paths (gravcal/kernels/simd.hpp)
    if (way == 4 && !gravcal::use_avx2()) break;
    struct Avx2Off {
      bool on;
      ~Avx2Off() {
        if (on) gravcal::set_avx2(true);
      }
    } restore{way == 4};
    if (way == 4) gravcal::set_avx2(false);
    std::vector<double> buf(3 * (static_cast<std::size_t>(L) + 3)), held(buf.size());
    gravcal::LazySd state;
    gravcal::Segmenter seg(L, false);
    if (compat && !seg.use_r_arithmetic(buf.data(), buf.size())) __builtin_trap();
    // ways 0-2 lazy when asked; way 3: R's sds everywhere, as the reference
    if (lazy && way != 3 && !seg.lazy_r_sd(max_sd, &state, held.data(), held.size())) __builtin_trap();
    gravcal::GgirBlocks gb(seg, per_hour, compat, with_t);
    auto sink = [&](const gravcal::WindowStats& w) { out[way].w.push_back(w); };
    std::size_t c = 0;
    for (const std::vector<double>& b : blocks) {
      const std::size_t n = b.size() / 4;
      std::vector<double> x(n), y(n), z(n), t(n);
      for (std::size_t i = 0; i < n; ++i) {
        x[i] = b[4 * i];
        y[i] = b[4 * i + 1];
        z[i] = b[4 * i + 2];
        t[i] = b[4 * i + 3];
      }
      gb.begin_block();
      std::size_t i = 0;
      if (way == 0 || way == 3 || way == 4) {
        gb.push(x.data(), y.data(), z.data(), with_t ? t.data() : nullptr, n, sink);
        i = n;
      }
      while (i < n) {
        std::size_t m = std::min(chunks[c++ % chunks.size()], n - i);
        if (way == 1) {
          gb.push(x.data() + i, y.data() + i, z.data() + i,
                  with_t ? t.data() + i : nullptr, m, sink);
        } else {
          // a decoder that fills at most the room given, maybe less
          const gravcal::BlockSpace s = gb.space(m == 0 ? 1 : m);
          if (s.capacity < 1) __builtin_trap();
          m = std::min(m, s.capacity);
          for (std::size_t j = 0; j < m; ++j) {
            s.x[j] = x[i + j];
            s.y[j] = y[i + j];
            s.z[j] = z[i + j];
            if (s.t != nullptr) s.t[j] = t[i + j];
          }
          gb.commit(m, with_t, sink);
        }
        i += m;
      }
      const gravcal::GgirBlockInfo r = gb.end_block(sink);
      if (r.used % hour != 0 || r.used > r.ld ||
          r.zeros > r.rows || r.carried < 0) {
        __builtin_trap();
      }
      out[way].b.push_back(r);
    }
  }
  if (lazy) {
    const std::vector<gravcal::WindowStats>& a = out[0].w;  // lazy
    const std::vector<gravcal::WindowStats>& e = out[3].w;  // R's sds
    if (a.size() != e.size()) __builtin_trap();
    gravcal::SdRestRule rule;
    rule.max_sd = max_sd;
    std::size_t last = a.size();  // the last window with means
    for (std::size_t k = 0; k < a.size(); ++k) {
      gravcal::WindowStats u = a[k];
      std::memcpy(u.sd, e[k].sd, sizeof u.sd);
      if (std::memcmp(&u, &e[k], sizeof u) != 0) __builtin_trap();
      const bool r = gravcal::is_rest(e[k], rule);
      if (r != gravcal::is_rest(a[k], rule)) __builtin_trap();
      if (r && std::memcmp(a[k].sd, e[k].sd, sizeof u.sd) != 0) __builtin_trap();
      if (std::isnan(e[k].mean[2]) || std::isnan(e[k].mean_norm)) continue;
      if (last < a.size()) {
        for (int ax = 0; ax < 3; ++ax) {
          if ((a[k].sd[ax] == a[last].sd[ax]) != (e[k].sd[ax] == e[last].sd[ax]))
            __builtin_trap();
        }
      }
      last = k;
    }
  }
  for (int way = 1; way < 5; ++way) {
    if (way == 3 || (way == 4 && !gravcal::use_avx2())) continue;
    if (out[way].w.size() != out[0].w.size() || out[way].b.size() != out[0].b.size())
      __builtin_trap();
    for (std::size_t k = 0; k < out[0].w.size(); ++k) {
      if (std::memcmp(&out[way].w[k], &out[0].w[k], sizeof(gravcal::WindowStats)) != 0)
        __builtin_trap();
    }
    for (std::size_t k = 0; k < out[0].b.size(); ++k) {
      if (!same_info(out[way].b[k], out[0].b[k])) __builtin_trap();
    }
  }
  return 0;
}
