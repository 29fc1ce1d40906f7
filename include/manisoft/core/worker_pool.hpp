// WorkerPool: a small persistent pool of threads that runs one job over a fixed number of parts,
// for batched environments that step many independent simulations per call.
//
//   WorkerPool pool(2);                       // threads started once, joined by the destructor
//   pool.run(job);        // job(part, parts): part 0 on the caller, parts 1.. on the workers
//   pool.run(job, 1);     // fewer parts (a small batch): here no worker is woken
//
// `threads` = 1 runs every job on the caller's thread and starts no worker. run() returns when
// every part has finished; an exception thrown by any part is rethrown on the caller (the lowest
// part's first) after all parts have finished, never std::terminate. Waking the workers and
// waiting for them allocates nothing (a mutex and two condition variables, no std::function).
// run() is not reentrant: one job at a time per pool.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

#include "manisoft/core/error.hpp"

namespace manisoft {

class WorkerPool {
 public:
  explicit WorkerPool(int threads) : threads_(threads) {
    if (threads < 1) detail::fail("WorkerPool: threads = ", threads, " must be >= 1");
    errors_.resize(std::size_t(threads));
    workers_.reserve(std::size_t(threads - 1));
    for (int part = 1; part < threads; ++part) workers_.emplace_back([this, part] { work(part); });
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;
  ~WorkerPool() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (std::thread& t : workers_) t.join();
  }

  int threads() const { return threads_; }

  /// Calls job(part, parts) for every part < parts (1 <= parts <= threads(); default: all), part 0
  /// on the calling thread; the workers beyond `parts` do no work. Rethrows the first part's
  /// exception once all parts are done.
  template <typename Job>
  void run(Job& job, int parts = 0) {
    if (parts == 0) parts = threads_;
    if (parts < 1 || parts > threads_) detail::fail("WorkerPool::run: parts = ", parts, " must be in [1, threads = ", threads_, "]");
    {
      std::lock_guard lock(mutex_);  // a worker left out of the last job may still read parts_
      job_ = [](void* context, int part, int n) { (*static_cast<Job*>(context))(part, n); };
      context_ = &job;
      parts_ = parts;
      pending_ = parts - 1;
      if (parts > 1) ++generation_;
    }
    if (parts > 1) wake_.notify_all();
    run_part(0);
    if (parts > 1) {
      std::unique_lock lock(mutex_);
      done_.wait(lock, [this] { return pending_ == 0; });
    }
    for (std::exception_ptr& error : errors_) {
      if (!error) continue;
      std::exception_ptr first = error;
      for (std::exception_ptr& e : errors_) e = nullptr;
      std::rethrow_exception(first);
    }
  }

 private:
  void run_part(int part) {
    try {
      job_(context_, part, parts_);
    } catch (...) {
      errors_[std::size_t(part)] = std::current_exception();
    }
  }

  void work(int part) {
    std::uint64_t seen = 0;
    std::unique_lock lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || generation_ != seen; });
      if (stop_) return;
      seen = generation_;
      if (part >= parts_) continue;  // not needed for this job
      lock.unlock();
      run_part(part);
      lock.lock();
      if (--pending_ == 0) done_.notify_one();
    }
  }

  int threads_;
  std::vector<std::thread> workers_;
  std::vector<std::exception_ptr> errors_;  ///< one per part, written only by that part
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  std::uint64_t generation_ = 0;  ///< guarded by mutex_: one more per job
  int pending_ = 0;               ///< guarded by mutex_: workers still running the job
  bool stop_ = false;             ///< guarded by mutex_
  int parts_ = 1;                 ///< guarded by mutex_ (written): parts of the running job
  void (*job_)(void*, int, int) = nullptr;  ///< written under mutex_ while no worker runs
  void* context_ = nullptr;
};

}  // namespace manisoft
