#include "core/interrupt_cleanup.h"

#include <pthread.h>
#include <signal.h>

#include <algorithm>
#include <filesystem>
#include <mutex>
#include <thread>
#include <vector>

namespace fibscope {
namespace {

namespace fs = std::filesystem;

struct Registry {
  std::mutex mutex;
  std::vector<std::string> paths;
};

Registry& registry() {
  static Registry* r = new Registry;  // never destroyed: the watcher may use it at exit
  return *r;
}

// Under the registry's lock.
size_t removeAll(const std::vector<std::string>& paths) {
  size_t removed = 0;
  for (const std::string& path : paths) {
    std::error_code ec;
    if (fs::remove_all(path, ec) > 0) ++removed;
    // Siblings whose names extend the path (a library's own temporary
    // before its rename, e.g. libzip's "<archive>.XXXXXX").
    const fs::path p(path);
    const std::string prefix = p.filename().string();
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string name = it->path().filename().string();
      if (name.size() > prefix.size() && name.compare(0, prefix.size(), prefix) == 0) {
        std::error_code ignored;
        fs::remove_all(it->path(), ignored);
      }
    }
  }
  return removed;
}

}  // namespace

void registerTemporaryPath(const std::string& path) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  r.paths.push_back(path);
}

void unregisterTemporaryPath(const std::string& path) {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  const auto it = std::find(r.paths.rbegin(), r.paths.rend(), path);
  if (it != r.paths.rend()) r.paths.erase(std::next(it).base());
}

size_t removeTemporaryPathsForInterrupt() {
  Registry& r = registry();
  const std::lock_guard<std::mutex> lock(r.mutex);
  const size_t removed = removeAll(r.paths);
  r.paths.clear();
  return removed;
}

void installInterruptCleanup() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGINT);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
  std::thread([set] {
    int sig = 0;
    while (sigwait(&set, &sig) != 0) {
    }
    // The lock is kept: no thread registers (creates) another temporary
    // from here on, and the process ends below.
    Registry& r = registry();
    r.mutex.lock();
    removeAll(r.paths);
    // End as the signal would have: its default action, delivered to this
    // thread (the only one not blocking it once unblocked here).
    signal(sig, SIG_DFL);
    sigset_t one;
    sigemptyset(&one);
    sigaddset(&one, sig);
    pthread_sigmask(SIG_UNBLOCK, &one, nullptr);
    raise(sig);
  }).detach();
}

}  // namespace fibscope
