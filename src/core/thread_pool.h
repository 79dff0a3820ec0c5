// A fixed set of worker threads running submitted jobs in submission order
// of start (not of completion). Each job learns the index of the worker
// running it, so callers can keep per-worker state (an encoder, a meter)
// without locks. Exceptions thrown by a job reach the caller through the
// future.
#pragma once

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>
#include <vector>

namespace fibscope {

class ThreadPool {
 public:
  // threads == 0: one per hardware thread.
  explicit ThreadPool(unsigned threads = 0);
  ~ThreadPool();  // finishes the queued jobs, then joins
  ThreadPool(const ThreadPool&) = delete;
  ThreadPool& operator=(const ThreadPool&) = delete;

  unsigned size() const { return unsigned(workers_.size()); }
  std::future<void> submit(std::function<void(unsigned worker)> job);

  static unsigned hardwareThreads();

 private:
  void run(unsigned worker);
  std::vector<std::thread> workers_;
  std::deque<std::packaged_task<void(unsigned)>> queue_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
};

// Runs piece(0) .. piece(pieces - 1) at once: piece 0 on the calling thread,
// each other on a thread of its own, and returns when all are done; the
// first exception of a piece reaches the caller. For a few large pieces of
// one job (bands of an image, ranges of a copy), where a pool's queue buys
// nothing.
void runPieces(unsigned pieces, const std::function<void(unsigned)>& piece);

}  // namespace fibscope
