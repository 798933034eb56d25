// gravcal: no floating-point contraction, whatever the compiler's flags.
//
// The core's results are promised to the bit (GGIR's numbers, R's
// arithmetic, the same bits from the SIMD and portable paths). A compiler
// allowed to contract a * b + c into one fused multiply-add (GCC's default
// outside strict ISO mode, clang's within an expression, on any processor
// with FMA: -march=native) rounds once where R rounds twice. This header
// turns contraction off for every function defined after it in the
// translation unit: include it first (before any other header, so that the
// standard library's and Eigen's templates are compiled the same way and
// nothing stops inlining); the core's headers include it too.
//
// GCC: the pragma wins over -ffp-contract=fast on the command line. clang:
// -ffp-contract=fast and -ffast-math override the pragma; the R package
// probes its build when it loads (src/fp_probe.cpp) and refuses to promise
// GGIR's bits from such a build. No includes: standard C++ only.
#ifndef GRAVCAL_FP_CONTRACT_HPP
#define GRAVCAL_FP_CONTRACT_HPP

#if defined(__clang__)
#pragma clang fp contract(off)
#elif defined(__GNUC__)
#pragma GCC optimize("fp-contract=off")
#endif

#endif  // GRAVCAL_FP_CONTRACT_HPP
