// gravcal: whether the host's C++ library has threads. Where it has none
// (libstdc++ built for the win32 threads model, as Debian's default mingw
// compiler), GRAVCAL_NO_THREADS is defined and the work that would take a
// second thread (ggir_epochs.hpp short_metrics(), read_ahead.hpp,
// ggir_blocks.hpp's windows) runs on the caller's. Define it to build
// without threads anywhere. Header-only, standard headers only.
#ifndef GRAVCAL_HOST_THREADS_HPP
#define GRAVCAL_HOST_THREADS_HPP

#include <cstddef>  // (a standard header first: libstdc++'s configuration macros)

#if defined(__GLIBCXX__) && !defined(_GLIBCXX_HAS_GTHREADS) && !defined(GRAVCAL_NO_THREADS)
#define GRAVCAL_NO_THREADS 1
#endif

#ifndef GRAVCAL_NO_THREADS
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <system_error>
#include <thread>
#include <utility>

namespace gravcal {

// One job at a time on a thread of its own, in the order given: run()
// hands a job over once the one before it is done (raising that one's
// exception, if it had one); wait() waits for the job and raises its
// exception; settle() waits and forgets it (for a caller that is already
// leaving by an exception). The thread is made with the first job and
// joined by the destructor, after its job. A job touches no R object.
class Worker {
 public:
  Worker() = default;
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;
  ~Worker() {
    {
      const std::lock_guard<std::mutex> lock(m_);
      quit_ = true;
    }
    cv_.notify_all();
    if (t_.joinable()) t_.join();
  }
  // False, with nothing done, where no thread is to be had: the caller then
  // runs the job itself.
  bool run(std::function<void()> job) {
    wait();
    if (!t_.joinable()) {
      try {
        t_ = std::thread([this] { loop(); });
      } catch (const std::system_error&) {
        return false;
      }
    }
    {
      const std::lock_guard<std::mutex> lock(m_);
      job_ = std::move(job);
      busy_ = true;
    }
    cv_.notify_all();
    return true;
  }
  void wait() {
    std::unique_lock<std::mutex> lock(m_);
    cv_.wait(lock, [this] { return !busy_; });
    if (error_) {
      std::exception_ptr e = error_;
      error_ = nullptr;
      std::rethrow_exception(e);
    }
  }
  void settle() noexcept {
    std::unique_lock<std::mutex> lock(m_);
    cv_.wait(lock, [this] { return !busy_; });
    error_ = nullptr;
  }

 private:
  void loop() {
    std::unique_lock<std::mutex> lock(m_);
    for (;;) {
      cv_.wait(lock, [this] { return busy_ || quit_; });
      if (!busy_) return;  // quit, no job left
      std::function<void()> job = std::move(job_);
      lock.unlock();
      std::exception_ptr e;
      try {
        job();
      } catch (...) {
        e = std::current_exception();
      }
      lock.lock();
      error_ = e;
      busy_ = false;
      cv_.notify_all();
    }
  }
  std::mutex m_;
  std::condition_variable cv_;
  std::function<void()> job_;
  bool busy_ = false, quit_ = false;
  std::exception_ptr error_;
  std::thread t_;
};

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
