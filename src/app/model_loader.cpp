#include "app/model_loader.h"

#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <new>

#include "app/open_input.h"
#include "codec/fbl_cache.h"
#include "codec/fbl_codec.h"
#include "codec/fiblet_decoder.h"
#include "core/error.h"
#include "io/reader.h"
#include "phantom/phantom.h"

namespace fibscope {
namespace {

using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

// Forwards a reader and stops it between chunks once `cancel` is set: the
// compressor reads on its own thread and unwinds on the exception, removing
// its temporary file (FblWriter), so a cancelled load leaves nothing.
class CancellableReader : public TractogramReader {
 public:
  CancellableReader(std::unique_ptr<TractogramReader> inner, const std::atomic<bool>* cancel)
      : inner_(std::move(inner)), cancel_(cancel) {
    header_ = inner_->header();
    warnings_ = inner_->warnings();
  }
  bool read(Tractogram& chunk, size_t max_points) override {
    if (cancel_ && cancel_->load(std::memory_order_relaxed)) fail(header_.path.empty() ? "load" : header_.path, "cancelled");
    const bool more = inner_->read(chunk, max_points);
    warnings_ = inner_->warnings();
    return more;
  }
  uint64_t bytesRead() const override { return inner_->bytesRead(); }

 private:
  std::unique_ptr<TractogramReader> inner_;
  const std::atomic<bool>* cancel_;
};

void checkCancel(const std::atomic<bool>* cancel, const std::string& name) {
  if (cancel && cancel->load(std::memory_order_relaxed)) fail(name, "cancelled");
}

void report(const Progress::Sink& sink, const std::string& label) {
  if (!sink) return;
  ProgressSnapshot s;
  s.label = label;
  sink(s);
}

// Compresses into a temporary file that is unlinked once mapped (use_cache
// off): the map keeps the data alive, nothing stays on disk.
FblCacheEntry compressUncached(const ReaderFactory& open, const CompressOptions& options) {
  std::error_code ec;
  std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
  if (ec) dir = "/tmp";
  static std::atomic<uint64_t> counter{0};
  const std::string path =
      (dir / ("fibscope-load-" + std::to_string(::getpid()) + "-" + std::to_string(counter.fetch_add(1)) + ".fbl"))
          .string();
  FblCacheEntry entry;
  CompressOptions o = options;
  o.overwrite = true;
  entry.report = compressTractogram(open, path, o);
  try {
    entry.file = FblFile::open(path);
    entry.file.verify();
  } catch (...) {
    std::filesystem::remove(path, ec);
    throw;
  }
  std::filesystem::remove(path, ec);
  entry.temporary = true;
  entry.warnings = entry.report.warnings;
  return entry;
}

}  // namespace

void fblBoundsAndSample(const FblFile& file, size_t sample_count, Bounds& bounds, std::vector<Vec3d>& sample) {
  const CodecParams params = codecParamsFromFbl(file.header(), file.path());
  const FibletDecoder decoder(params);
  const std::span<const uint8_t> records = file.data(kFblSectionFiblets);
  const uint32_t record_bytes = params.recordBytes();
  const uint32_t n = params.points_per_fiblet;
  const uint64_t fiblets = records.size() / record_bytes;
  bounds = Bounds{};
  sample.clear();
  if (fiblets == 0) return;

  auto countOf = [&](uint64_t i) -> uint32_t {
    return shader::fibletCount(records[i * record_bytes + shader::fibletFlagsByte(n)]);
  };
  auto storedPoint = [&](uint64_t i, int which, float* p) {
    const uint8_t* r = records.data() + i * record_bytes + 6 * which;
    for (int c = 0; c < 3; ++c) p[c] = shader::fibletDequantize(uint32_t(r[2 * c]) | uint32_t(r[2 * c + 1]) << 8);
  };

  // Pass 1: the exact box of the stored points (points 0 and 1 of every
  // fiblet, 16-bit in the record: no decoding).
  std::array<float, 3> lo, hi;
  lo.fill(std::numeric_limits<float>::infinity());
  hi.fill(-std::numeric_limits<float>::infinity());
  auto grow = [&](const float* p) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], p[c]);
      hi[c] = std::max(hi[c], p[c]);
    }
  };
  for (uint64_t i = 0; i < fiblets; ++i) {
    const uint32_t count = countOf(i);
    if (count < 1 || count > n) continue;  // the reader rejects these; never decoded
    float p[3];
    storedPoint(i, 0, p);
    grow(p);
    if (count >= 2) {
      storedPoint(i, 1, p);
      grow(p);
    }
  }
  // Pass 2: point k >= 2 of a fiblet lies within (k - 1) steps of point 1,
  // so only fiblets whose reach crosses a face of the box so far can widen
  // it: decode those (a few percent of a brain; the box only grows, so a
  // fiblet skipped earlier stays inside). The reach has a margin for the
  // float rounding of the composed frames.
  std::array<float, 3 * shader::kFibletMaxPoints> xyz;
  for (uint64_t i = 0; i < fiblets; ++i) {
    const uint32_t count = countOf(i);
    if (count < 3 || count > n) continue;
    float p1[3];
    storedPoint(i, 1, p1);
    const float reach = float(count - 2) * params.delta * 1.001f + 1e-6f;
    bool inside = true;
    for (int c = 0; c < 3; ++c) inside = inside && p1[c] - reach >= lo[c] && p1[c] + reach <= hi[c];
    if (inside) continue;
    const uint32_t decoded = decoder.decodeSequential(records.data() + i * record_bytes, xyz.data());
    for (uint32_t k = 2; k < decoded; ++k) grow(&xyz[3 * k]);
  }
  if (!(lo[0] <= hi[0])) return;  // no valid fiblet
  bounds.min = decoder.toWorld(lo.data());
  bounds.max = decoder.toWorld(hi.data());

  // The sample: evenly spaced fiblets, a few evenly spaced points of each
  // (the GPU's Scan order is within 1e-6 of the scene of these points).
  if (sample_count == 0) return;
  const uint64_t picks = std::min<uint64_t>(fiblets, sample_count);
  const uint64_t per = (sample_count + picks - 1) / picks;
  sample.reserve(picks * per);
  for (uint64_t j = 0; j < picks; ++j) {
    const uint64_t i = j * fiblets / picks;
    const uint32_t decoded = decoder.decodeSequential(records.data() + i * record_bytes, xyz.data());
    if (decoded == 0) continue;
    const uint64_t take = std::min<uint64_t>(per, decoded);
    for (uint64_t t = 0; t < take; ++t) {
      // Offset by j so that one-per-fiblet samples do not all sit at the
      // fiblets' starts.
      const uint64_t k = (t * decoded / take + j) % decoded;
      sample.push_back(decoder.toWorld(&xyz[3 * k]));
    }
  }
}

ModelData loadModel(const std::string& path, const ModelLoaderOptions& options, const std::atomic<bool>* cancel,
                    const Progress::Sink& progress_sink, FblCache* shared_cache) {
  const auto start = Clock::now();
  ModelData model;
  model.source_path = path;
  CompressOptions compress = options.compress;
  compress.terminal_progress = false;
  compress.progress_sink = progress_sink;
  std::optional<FblCache> own_cache;
  FblCache* cache = shared_cache;
  if (!cache && options.use_cache) cache = &own_cache.emplace(options.cache_dir, options.cache_max_bytes);

  FblCacheEntry entry;
  if (path.empty()) {
    PhantomOptions phantom;
    phantom.streamlines = options.phantom_streamlines;
    phantom.seed = options.phantom_seed;
    validatePhantomOptions(phantom);
    model.name = "phantom (" + std::to_string(phantom.streamlines) + " fibers)";
    const ReaderFactory open = [&]() {
      return std::unique_ptr<TractogramReader>(std::make_unique<CancellableReader>(openPhantom(phantom), cancel));
    };
    entry = cache ? cache->get(fblCacheKeyForPhantom(phantom, compress), open, compress)
                  : compressUncached(open, compress);
  } else {
    model.name = std::filesystem::path(path).filename().string();
    if (model.name.empty()) model.name = path;
    if (isFblPath(path)) {
      // Already compressed: opened as is.
      report(progress_sink, "opening");
      entry.file = FblFile::open(path);
      entry.file.verify();
      entry.from_cache = true;
      model.input_bytes = entry.file.fileBytes();
    } else {
      const ReaderFactory open = [&]() {
        return std::unique_ptr<TractogramReader>(std::make_unique<CancellableReader>(openTractogram(path), cancel));
      };
      if (cache) {
        report(progress_sink, "checking the cache");
        const FblCacheKey key = fblCacheKeyForFile(path, compress);
        model.input_bytes = key.size;
        entry = cache->get(key, open, compress);
      } else {
        entry = compressUncached(open, compress);
        model.input_bytes = entry.report.input_bytes;
      }
    }
  }
  checkCancel(cancel, path.empty() ? "phantom" : path);

  report(progress_sink, "measuring");
  const FblHeaderFields& h = entry.file.header();
  fblBoundsAndSample(entry.file, options.sample_points, model.bounds, model.sample);
  if (h.fiber_count == 0 || model.sample.empty())
    fail(path.empty() ? "phantom" : path, "no streamlines to show");
  // Segments: points - 1 per non-empty fiber (fiblets of a fiber share no
  // point, so the header's point count is the fibers' points).
  const std::span<const uint64_t> first = entry.file.array<uint64_t>(*entry.file.find(kFblSectionFiberFirstFiblet));
  uint64_t nonempty = 0;
  for (size_t f = 0; f + 1 < first.size(); ++f) nonempty += first[f + 1] > first[f] ? 1 : 0;
  model.streamlines = h.fiber_count;
  model.points = h.point_count;
  model.segments = h.point_count >= nonempty ? h.point_count - nonempty : 0;
  model.fiblets = h.fiblet_count;
  model.step_mm = h.delta_mm;
  model.fbl_bytes = entry.file.fileBytes();
  model.from_cache = entry.from_cache;
  model.temporary = entry.temporary;
  if (!entry.from_cache) {
    model.compress_seconds = entry.report.seconds();
    model.mean_error_um = entry.report.error.mean_um;
    model.max_error_um = entry.report.error.max_um;
  }
  model.warnings = std::move(entry.warnings);
  model.fbl = std::move(entry.file);
  model.seconds = secondsSince(start);
  return model;
}

ModelLoader::ModelLoader(ModelLoaderOptions options) : options_(std::move(options)) {
  if (options_.use_cache) cache_ = std::make_unique<FblCache>(options_.cache_dir, options_.cache_max_bytes);
  worker_ = std::thread([this] { run(); });
}

ModelLoader::~ModelLoader() {
  {
    std::lock_guard lock(mutex_);
    stop_ = true;
    queue_.clear();
    if (cancel_running_) cancel_running_->store(true);
  }
  wake_.notify_all();
  if (worker_.joinable()) worker_.join();
}

uint64_t ModelLoader::request(std::string path) {
  uint64_t id;
  {
    std::lock_guard lock(mutex_);
    id = next_id_++;
    queue_.push_back(Job{id, std::move(path)});
  }
  wake_.notify_all();
  return id;
}

std::vector<LoadEvent> ModelLoader::poll() {
  std::lock_guard lock(mutex_);
  std::vector<LoadEvent> out = std::move(events_);
  events_.clear();
  return out;
}

std::optional<LoadEvent> ModelLoader::wait(double timeout_seconds) {
  std::unique_lock lock(mutex_);
  finished_.wait_for(lock, std::chrono::duration<double>(timeout_seconds), [&] { return !events_.empty(); });
  if (events_.empty()) return std::nullopt;
  LoadEvent event = std::move(events_.front());
  events_.erase(events_.begin());
  return event;
}

std::vector<LoadProgress> ModelLoader::progress() const {
  std::lock_guard lock(mutex_);
  if (!running_) return {};
  return {LoadProgress{running_->id, running_->path, running_progress_}};
}

size_t ModelLoader::pending() const {
  std::lock_guard lock(mutex_);
  return queue_.size() + (running_ ? 1 : 0);
}

void ModelLoader::cancel(uint64_t id) {
  std::lock_guard lock(mutex_);
  if (running_ && running_->id == id && cancel_running_) cancel_running_->store(true);
  for (auto it = queue_.begin(); it != queue_.end(); ++it) {
    if (it->id != id) continue;
    LoadEvent event;
    event.id = id;
    event.path = it->path;
    event.cancelled = true;
    event.error = (it->path.empty() ? std::string("phantom") : it->path) + ": cancelled";
    events_.push_back(std::move(event));
    queue_.erase(it);
    finished_.notify_all();
    break;
  }
}

void ModelLoader::cancelAll() {
  std::vector<uint64_t> ids;
  {
    std::lock_guard lock(mutex_);
    for (const Job& job : queue_) ids.push_back(job.id);
    if (running_) ids.push_back(running_->id);
  }
  for (uint64_t id : ids) cancel(id);
}

void ModelLoader::run() {
  for (;;) {
    Job job;
    std::shared_ptr<std::atomic<bool>> flag;
    {
      std::unique_lock lock(mutex_);
      wake_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (stop_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      running_ = job;
      flag = cancel_running_ = std::make_shared<std::atomic<bool>>(false);
      running_progress_ = ProgressSnapshot{};
      running_progress_.label = "starting";
    }
    LoadEvent event = load(job, *flag);
    {
      std::lock_guard lock(mutex_);
      running_.reset();
      cancel_running_.reset();
      if (stop_) return;  // nobody polls any more
      events_.push_back(std::move(event));
    }
    finished_.notify_all();
  }
}

LoadEvent ModelLoader::load(const Job& job, const std::atomic<bool>& cancel) {
  LoadEvent event;
  event.id = job.id;
  event.path = job.path;
  const std::string name = job.path.empty() ? std::string("phantom") : job.path;
  const Progress::Sink sink = [this, id = job.id](const ProgressSnapshot& s) {
    std::lock_guard lock(mutex_);
    if (running_ && running_->id == id) running_progress_ = s;
  };
  try {
    event.model = std::make_unique<ModelData>(loadModel(job.path, options_, &cancel, sink, cache_.get()));
  } catch (const Error& e) {
    event.error = oneLine(e.what());
  } catch (const std::bad_alloc&) {
    event.error = name + ": out of memory while loading";
  } catch (const std::exception& e) {
    event.error = oneLine(name + ": " + e.what());
  }
  if (!event.model && cancel.load()) {
    event.cancelled = true;
    event.error = name + ": cancelled";
  }
  return event;
}

}  // namespace fibscope
