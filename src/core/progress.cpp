#include "core/progress.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace fibscope {

std::string formatCount(double v) {
  char buf[64];
  const char* suffix[] = {"", " k", " M", " G", " T"};
  int i = 0;
  while (std::fabs(v) >= 1000.0 && i < 4) {
    v /= 1000.0;
    ++i;
  }
  if (i == 0)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%.*f%s", std::fabs(v) < 10 ? 2 : (std::fabs(v) < 100 ? 1 : 0), v, suffix[i]);
  return buf;
}

std::string formatBytes(double b) {
  char buf[64];
  const char* suffix[] = {"B", "KiB", "MiB", "GiB", "TiB"};
  int i = 0;
  while (b >= 1024.0 && i < 4) {
    b /= 1024.0;
    ++i;
  }
  std::snprintf(buf, sizeof buf, i == 0 ? "%.0f %s" : "%.2f %s", b, suffix[i]);
  return buf;
}

std::string formatDuration(double s) {
  char buf[64];
  if (s < 0 || !std::isfinite(s)) return "?";
  if (s < 60)
    std::snprintf(buf, sizeof buf, "%.0f s", std::ceil(s));
  else if (s < 3600)
    std::snprintf(buf, sizeof buf, "%d min %02d s", int(s) / 60, int(s) % 60);
  else
    std::snprintf(buf, sizeof buf, "%d h %02d min", int(s) / 3600, (int(s) / 60) % 60);
  return buf;
}

std::string formatProgressLine(const ProgressSnapshot& s, int bar_width) {
  std::string line = s.label;
  const bool bytes = s.unit == "bytes";
  auto amount = [&](double v) { return bytes ? formatBytes(v) : formatCount(v) + " " + s.unit; };
  if (s.total > 0) {
    const double f = std::min(1.0, s.done / s.total);
    const int filled = static_cast<int>(f * bar_width);
    line += "  [" + std::string(filled, '#') + std::string(bar_width - filled, '.') + "]";
    char pct[16];
    std::snprintf(pct, sizeof pct, " %5.1f%%", 100.0 * f);
    line += pct;
  }
  line += "  " + amount(s.done);
  line += "  " + (bytes ? formatBytes(s.rate) + "/s" : formatCount(s.rate) + " " + s.unit + "/s");
  if (s.finished)
    line += "  in " + formatDuration(s.elapsed_seconds);
  else if (s.eta_seconds >= 0)
    line += "  ETA " + formatDuration(s.eta_seconds);
  return line;
}

Progress::Progress(std::string label, double total, std::string unit, bool terminal, Sink sink)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      total_(total),
      start_(std::chrono::steady_clock::now()),
      terminal_(terminal && ::isatty(STDERR_FILENO)),
      sink_(std::move(sink)) {}

Progress::~Progress() {
  if (!finished_ && terminal_) std::fputc('\n', stderr);
}

void Progress::add(double delta) {
  done_.fetch_add(delta, std::memory_order_relaxed);
  maybeReport(false);
}

void Progress::set(double done) {
  done_.store(done, std::memory_order_relaxed);
  maybeReport(false);
}

void Progress::setTotal(double total) { total_.store(total, std::memory_order_relaxed); }

ProgressSnapshot Progress::snapshot() const {
  ProgressSnapshot s;
  s.label = label_;
  s.unit = unit_;
  s.done = done_.load(std::memory_order_relaxed);
  s.total = total_.load(std::memory_order_relaxed);
  s.elapsed_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  s.rate = s.elapsed_seconds > 0 ? s.done / s.elapsed_seconds : 0;
  if (s.total > 0 && s.rate > 0) s.eta_seconds = std::max(0.0, (s.total - s.done) / s.rate);
  s.finished = finished_;
  return s;
}

void Progress::maybeReport(bool force) {
  if (!terminal_ && !sink_) return;
  const int64_t now =
      std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - start_).count();
  int64_t last = last_report_ns_.load(std::memory_order_relaxed);
  if (!force && now - last < 100'000'000) return;
  if (!force && !last_report_ns_.compare_exchange_strong(last, now)) return;
  std::lock_guard lock(report_mutex_);
  const ProgressSnapshot s = snapshot();
  if (terminal_) std::fprintf(stderr, "\r\033[K%s", formatProgressLine(s).c_str());
  if (sink_) sink_(s);
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  maybeReport(true);
  if (terminal_) std::fputc('\n', stderr);
}

}  // namespace fibscope
