// Progress of long work (reading, generating, compressing) with rate and ETA.
//
// Work code calls add()/set() from any thread (atomic, cheap); the report is
// drawn at most every 100 ms, on stderr when it is a terminal, and/or handed
// to a sink (the viewer's progress bar). Nothing is printed when stderr is
// not a terminal and no sink is set, so scripts and tests stay quiet.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>

namespace fibscope {

struct ProgressSnapshot {
  std::string label;
  std::string unit;       // what is counted: "points", "bytes", ...
  double done = 0;
  double total = 0;       // 0 when unknown
  double rate = 0;        // units per second since start
  double eta_seconds = -1;  // -1 when unknown
  double elapsed_seconds = 0;
  bool finished = false;
};

// "12.3 M points/s" style numbers.
std::string formatCount(double value);
std::string formatBytes(double bytes);
std::string formatDuration(double seconds);
// One line: "label  [#####.....]  45.1%  12.3 M points  8.1 M points/s  ETA 4 s"
std::string formatProgressLine(const ProgressSnapshot& s, int bar_width = 24);

class Progress {
 public:
  using Sink = std::function<void(const ProgressSnapshot&)>;
  // `terminal`: draw on stderr (only honoured when stderr is a terminal).
  Progress(std::string label, double total, std::string unit, bool terminal = true, Sink sink = {});
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;

  void add(double delta);
  void set(double done);
  void setTotal(double total);
  // Draws the final line (with the average rate) and stops reporting.
  void finish();
  ProgressSnapshot snapshot() const;

 private:
  void maybeReport(bool force);
  std::string label_;
  std::string unit_;
  std::atomic<double> done_{0};
  std::atomic<double> total_{0};
  std::chrono::steady_clock::time_point start_;
  std::atomic<int64_t> last_report_ns_{0};
  bool terminal_ = false;
  bool finished_ = false;
  Sink sink_;
  std::mutex report_mutex_;
};

}  // namespace fibscope
