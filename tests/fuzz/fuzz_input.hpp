// Reading a fuzzer's bytes as the values a harness needs.
#ifndef GRAVCAL_FUZZ_INPUT_HPP
#define GRAVCAL_FUZZ_INPUT_HPP
#include <cstddef>
#include <cstdint>
#include <cstring>

struct FuzzInput {
  const std::uint8_t* p;
  std::size_t n;
  bool empty() const { return n == 0; }
  std::uint8_t byte() {
    if (!n) return 0;
    --n;
    return *p++;
  }
  // any double, NaN and infinities included
  double raw_double() {
    std::uint64_t u = 0;
    for (int i = 0; i < 8; ++i) u = (u << 8) | byte();
    double d;
    std::memcpy(&d, &u, sizeof d);
    return d;
  }
  // mostly plausible values (within +-16 g, steps of 1/4096), sometimes raw
  double sample() {
    const std::uint8_t k = byte();
    if (k < 16) return raw_double();
    const std::int16_t v = static_cast<std::int16_t>((byte() << 8) | byte());
    return v / 2048.0;
  }
};
#endif
