// gravcal: whether the host's C++ library has threads. Where it has none
// (libstdc++ built for the win32 threads model, as Debian's default mingw
// compiler), GRAVCAL_NO_THREADS is defined and the work that would take a
// second thread (ggir_epochs.hpp short_metrics(), read_ahead.hpp) runs on
// the caller's. Define it to build without threads anywhere. Header-only,
// standard headers only.
#ifndef GRAVCAL_HOST_THREADS_HPP
#define GRAVCAL_HOST_THREADS_HPP

#include <cstddef>  // (a standard header first: libstdc++'s configuration macros)

#if defined(__GLIBCXX__) && !defined(_GLIBCXX_HAS_GTHREADS) && !defined(GRAVCAL_NO_THREADS)
#define GRAVCAL_NO_THREADS 1
#endif

#ifndef GRAVCAL_NO_THREADS
#include <thread>

namespace gravcal {

// Joins the thread when the scope is left, whatever leaves it (declare what
// the thread reads before the guard, so that it outlives the thread).
struct JoinGuard {
  std::thread& t;
  ~JoinGuard() {
    if (t.joinable()) t.join();
  }
};

}  // namespace gravcal
#endif

#endif  // GRAVCAL_HOST_THREADS_HPP
