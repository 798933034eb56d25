// libFuzzer harness: the streaming segmenter fed arbitrary values in
// arbitrary chunks. Checks, besides the sanitizers' findings: the windows are
// the same, to the bit, however the stream is cut (whole versus in the
// fuzzer's chunks), in streaming and in R-compatible arithmetic; every
// window has a sane sample count.
#include <cstring>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/host/segmenter.hpp"

static bool same(const gravcal::WindowStats& a, const gravcal::WindowStats& b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  const double L = 1 + in.byte() % 40 + in.byte() / 256.0;  // samples per window
  const bool skip_zero = in.byte() & 1;
  const bool r_arith = in.byte() & 1;
  const bool with_t = in.byte() & 1;
  std::vector<std::size_t> chunks;
  for (int i = 0; i < 8; ++i) chunks.push_back(1 + in.byte() % 97);
  std::vector<double> x, y, z, t;
  while (!in.empty() && x.size() < 4000) {
    const std::uint8_t k = in.byte();
    double v[4];
    for (double& c : v) c = in.sample();
    if (k % 5 == 0) v[0] = v[1] = v[2] = 0.0;  // idle-sleep zeros
    x.push_back(v[0]);
    y.push_back(v[1]);
    z.push_back(v[2]);
    t.push_back(v[3]);
  }
  const std::size_t n = x.size();
  const double* tp = with_t ? t.data() : nullptr;
  std::vector<double> buf1(3 * (static_cast<std::size_t>(L) + 3)),
      buf2(buf1.size());
  gravcal::Segmenter s1(L, skip_zero), s2(L, skip_zero);
  if (r_arith) {
    if (!s1.use_r_arithmetic(buf1.data(), buf1.size())) __builtin_trap();
    if (!s2.use_r_arithmetic(buf2.data(), buf2.size())) __builtin_trap();
  }
  std::vector<gravcal::WindowStats> a, b;
  s1.push(x.data(), y.data(), z.data(), tp, n,
          [&](const gravcal::WindowStats& w) { a.push_back(w); });
  std::size_t i = 0, c = 0;
  while (i < n) {
    const std::size_t m = std::min(chunks[c++ % chunks.size()], n - i);
    s2.push(x.data() + i, y.data() + i, z.data() + i, tp ? tp + i : nullptr, m,
            [&](const gravcal::WindowStats& w) { b.push_back(w); });
    i += m;
  }
  if (a.size() != b.size()) __builtin_trap();
  for (std::size_t k = 0; k < a.size(); ++k) {
    // NaN statistics compare by their bits, which memcmp does
    if (!same(a[k], b[k])) __builtin_trap();
    if (a[k].n < 1 || a[k].n > static_cast<int>(L) + 2) __builtin_trap();
    if (a[k].n_invalid < 0 || a[k].n_invalid > a[k].n) __builtin_trap();
  }
  return 0;
}
