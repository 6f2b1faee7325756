// A fixed set of threads that run a batch of tasks and wait for all of them (internal).
#pragma once

#include <condition_variable>
#include <cstddef>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace mvog {
namespace detail {

/// `threads` - 1 workers started once; the thread calling run() is the last worker. Threads are
/// created once, not per batch: an insertion runs two batches per scan.
class ThreadPool {
 public:
  explicit ThreadPool(std::size_t threads);
  ~ThreadPool();
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  std::size_t threads() const { return workers_.size() + 1; }
  /// Calls task(worker, k) for every k in [0, count), each once, spread over the threads
  /// (worker in [0, threads()) tells which), and returns when all have returned. The first
  /// exception a task throws is rethrown here once the batch is over.
  void run(std::size_t count, const std::function<void(std::size_t, std::size_t)>& task);

 private:
  void work(std::size_t worker);
  void drain(std::size_t worker);

  std::vector<std::thread> workers_;
  std::mutex mutex_;
  std::condition_variable wake_;
  std::condition_variable done_;
  const std::function<void(std::size_t, std::size_t)>* task_ = nullptr;
  std::size_t count_ = 0;
  std::size_t next_ = 0;      // the next task to hand out
  std::size_t finished_ = 0;  // tasks returned
  std::size_t batch_ = 0;     // increases with every run()
  std::exception_ptr error_;
  bool stopping_ = false;
};

}  // namespace detail
}  // namespace mvog
