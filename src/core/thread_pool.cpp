#include "core/thread_pool.h"

#include <algorithm>
#include <exception>
#include <utility>

namespace fibscope {

unsigned ThreadPool::hardwareThreads() { return std::max(1u, std::thread::hardware_concurrency()); }

ThreadPool::ThreadPool(unsigned threads) {
  const unsigned n = threads ? threads : hardwareThreads();
  workers_.reserve(n);
  for (unsigned i = 0; i < n; ++i) workers_.emplace_back([this, i] { run(i); });
}

ThreadPool::~ThreadPool() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  for (std::thread& t : workers_) t.join();
}

std::future<void> ThreadPool::submit(std::function<void(unsigned)> job) {
  std::packaged_task<void(unsigned)> task(std::move(job));
  std::future<void> done = task.get_future();
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(std::move(task));
  }
  wake_.notify_one();
  return done;
}

void ThreadPool::run(unsigned worker) {
  for (;;) {
    std::packaged_task<void(unsigned)> task;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [this] { return stopping_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopping, and nothing left
      task = std::move(queue_.front());
      queue_.pop_front();
    }
    task(worker);  // an exception is stored in the task's future
  }
}

void runPieces(unsigned pieces, const std::function<void(unsigned)>& piece) {
  std::vector<std::future<void>> others;
  for (unsigned i = 1; i < pieces; ++i) others.push_back(std::async(std::launch::async, piece, i));
  std::exception_ptr error;
  try {
    if (pieces > 0) piece(0);
  } catch (...) {
    error = std::current_exception();
  }
  for (auto& other : others) {
    try {
      other.get();
    } catch (...) {
      if (!error) error = std::current_exception();
    }
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace fibscope
