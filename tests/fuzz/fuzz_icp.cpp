// libFuzzer harness: GGIR's ICP fit (icp.hpp, Eigen) on arbitrary points and
// temperatures, both stop rules, with and without temperature. Checks: no
// sanitizer finding, iterations within bounds, a fit reported finite has
// finite coefficients.
#include <cmath>
#include <vector>

#include "fuzz_input.hpp"
#include "gravcal/ggir/icp.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  FuzzInput in{data, size};
  gravcal::IcpConfig cfg;
  cfg.max_iter = in.byte() % 50;
  const std::uint8_t flags = in.byte();
  cfg.use_temp = flags & 1;
  cfg.stop = (flags & 2) ? gravcal::StopRule::parameters : gravcal::StopRule::ggir;
  cfg.r_arithmetic = flags & 4;
  std::vector<double> x, y, z, t;
  while (!in.empty() && x.size() < 200) {
    x.push_back(in.sample());
    y.push_back(in.sample());
    z.push_back(in.sample());
    t.push_back(20 + in.sample());
  }
  const gravcal::IcpResult r =
      gravcal::fit_icp(x.data(), y.data(), z.data(), t.data(), x.size(), cfg);
  if (r.iterations < 0 || r.iterations > cfg.max_iter) __builtin_trap();
  if (r.finite && r.iterations > 0) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(r.scale[k]) || !std::isfinite(r.offset[k]) ||
          !std::isfinite(r.tempoffset[k])) __builtin_trap();
    }
  }
  return 0;
}
