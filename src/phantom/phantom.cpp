// Phantom options, the per-streamline generator, and the streaming reader
// that runs it on worker threads.
#include "phantom/phantom.h"

#include <algorithm>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <exception>
#include <mutex>
#include <thread>

#include "core/error.h"
#include "phantom/phantom_internal.h"

namespace fibscope {

using namespace phantom_detail;

namespace {

constexpr std::array<std::string_view, kPhantomBundleCount> kBundleNames = {
    "corpus_callosum", "cst_left",  "cst_right",  "arcuate_left", "arcuate_right", "cingulum_left",
    "cingulum_right",  "ifof_left", "ifof_right", "ilf_left",     "ilf_right",     "u_fibers",
    "wm_commissural",  "wm_association", "wm_projection"};

// The named bundles' shares: the corpus callosum and U-fibers dominate, the
// left arcuate is larger than the right. Alone (kNamedBundleWeights) they
// make the mean fiber about 86 mm long, as in the fiblets paper's 500 k
// iFOD1 tractogram (0.43 G segments at 0.1 mm).
constexpr std::array<double, kPhantomBundleCount> kNamedBundleWeights = {
    0.24,          // corpus callosum
    0.065, 0.065,  // corticospinal
    0.065, 0.05,   // arcuate (left-lateralised)
    0.04,  0.04,   // cingulum
    0.04,  0.04,   // IFOF
    0.035, 0.035,  // ILF
    0.20,          // U-fibers
    0.0,   0.0,  0.0,  // the white matter at large: none
};

// The default, whole-brain mix: the same named bundles (1 of 7 in weight)
// beside the white-matter families at 2.1, 2.1 and 1.8, so 87 % of the
// fibers spread through the white matter as whole-brain tracking's do
// (docs/BENCHMARKS.md, "Phantom density": the density statistic of MRtrix3
// iFOD1 on the same fields, and its two-phase drawn fraction within 3.2
// points). The mean fiber is about 107 mm long.
constexpr std::array<double, kPhantomBundleCount> kWholeBrainWeights = {
    0.24, 0.065, 0.065, 0.065, 0.05, 0.04, 0.04, 0.04, 0.04, 0.035, 0.035, 0.20,
    2.1,  2.1,   1.8,
};

constexpr double kGuideSpacingMm = 1.0;
constexpr double kLookaheadMm = 4.0;
// Per-axis direction jitter per 0.1 mm step: turns of 2.5 degrees on
// average, a few above 7, so that fibers wander a fraction of a millimetre
// around their guide like probabilistic streamlines do.
constexpr double kJitterDegreesPerTenthMm = 2.0;
// A float coordinate inside the ellipsoid (|c| < 128 mm) is off by at most
// half an ulp, 2^-18 mm, per axis: at most sqrt(3) * 2^-18 mm in all.
constexpr double kFloatPositionError = 6.61e-6;

std::string number(double value) {
  char text[64];
  std::snprintf(text, sizeof text, "%.10g", value);
  return text;
}

std::string trimmed(const std::string& text) {
  const size_t first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return {};
  return text.substr(first, text.find_last_not_of(" \t") - first + 1);
}

void check(bool ok, const std::string& message) {
  if (!ok) throw Error("phantom: " + message);
}

}  // namespace

const std::array<std::string_view, kPhantomBundleCount>& phantomBundleNames() { return kBundleNames; }

int phantomBundleIndex(std::string_view name) {
  for (size_t i = 0; i < kBundleNames.size(); ++i)
    if (kBundleNames[i] == name) return int(i);
  return -1;
}

const std::array<double, kPhantomBundleCount>& defaultPhantomBundleWeights() { return kWholeBrainWeights; }

const std::array<double, kPhantomBundleCount>& namedBundlePhantomWeights() { return kNamedBundleWeights; }

void applyNamedBundlesPhantomMix(PhantomOptions& options) {
  options.bundle_weights.assign(kNamedBundleWeights.begin(), kNamedBundleWeights.end());
  options.bundle_radius_scale = 1.0;
}

void validatePhantomOptions(const PhantomOptions& o) {
  check(std::isfinite(o.bundle_radius_scale) && o.bundle_radius_scale >= 0.25 && o.bundle_radius_scale <= 4.0,
        "bundle_radius_scale must be between 0.25 and 4, got " + number(o.bundle_radius_scale));
  check(std::isfinite(o.step_mm) && o.step_mm >= 0.005 && o.step_mm <= 10.0,
        "step_mm must be between 0.005 and 10, got " + number(o.step_mm));
  check(std::isfinite(o.max_angle_deg) && o.max_angle_deg >= 1.0 && o.max_angle_deg <= 90.0,
        "max_angle_deg must be between 1 and 90, got " + number(o.max_angle_deg));
  check(std::isfinite(o.min_length_mm) && o.min_length_mm >= 0.0 && o.min_length_mm <= 150.0,
        "min_length_mm must be between 0 and 150 (the longest phantom bundles are about 170 mm), got " +
            number(o.min_length_mm));
  check(std::isfinite(o.max_length_mm) && o.max_length_mm >= o.min_length_mm && o.max_length_mm <= 10000.0,
        "max_length_mm must be between min_length_mm (" + number(o.min_length_mm) + ") and 10000, got " +
            number(o.max_length_mm));
  check(std::ceil(o.min_length_mm / o.step_mm - 1e-9) <= std::floor(o.max_length_mm / o.step_mm + 1e-9) &&
            o.max_length_mm >= o.step_mm,
        "no whole number of " + number(o.step_mm) + " mm steps gives a length between min_length_mm " +
            number(o.min_length_mm) + " and max_length_mm " + number(o.max_length_mm));
  check(std::isfinite(o.jitter) && o.jitter >= 0.0 && o.jitter <= 4.0,
        "jitter must be between 0 and 4, got " + number(o.jitter));
  check(o.threads <= 1024, "threads must be at most 1024, got " + std::to_string(o.threads));
  if (!o.bundle_weights.empty()) {
    check(o.bundle_weights.size() == kPhantomBundleCount,
          "bundle_weights must hold " + std::to_string(kPhantomBundleCount) + " values, got " +
              std::to_string(o.bundle_weights.size()));
    double sum = 0;
    for (size_t i = 0; i < kPhantomBundleCount; ++i) {
      check(std::isfinite(o.bundle_weights[i]) && o.bundle_weights[i] >= 0.0,
            "weight of bundle " + std::string(kBundleNames[i]) + " must be a finite number >= 0, got " +
                number(o.bundle_weights[i]));
      sum += o.bundle_weights[i];
    }
    check(sum > 0.0, "bundle weights are all 0");
  }
}

std::vector<double> parsePhantomBundleMix(const std::string& text, const std::vector<double>& base) {
  std::vector<double> weights(kWholeBrainWeights.begin(), kWholeBrainWeights.end());
  if (base.size() == kPhantomBundleCount) weights = base;
  size_t begin = 0;
  while (begin <= text.size()) {
    size_t end = text.find(',', begin);
    if (end == std::string::npos) end = text.size();
    const std::string entry = trimmed(text.substr(begin, end - begin));
    begin = end + 1;
    if (entry.empty()) continue;
    const size_t equals = entry.find('=');
    check(equals != std::string::npos, "bundle mix entry '" + entry + "' is not NAME=WEIGHT");
    const std::string name = trimmed(entry.substr(0, equals)), value = trimmed(entry.substr(equals + 1));
    const int index = phantomBundleIndex(name);
    if (index < 0) {
      std::string known;
      for (auto n : kBundleNames) known += (known.empty() ? "" : ", ") + std::string(n);
      check(false, "unknown bundle '" + name + "' in bundle mix (known: " + known + ")");
    }
    char* parse_end = nullptr;
    const double weight = std::strtod(value.c_str(), &parse_end);
    check(!value.empty() && parse_end == value.c_str() + value.size() && std::isfinite(weight) && weight >= 0.0,
          "weight '" + value + "' of bundle " + name + " is not a finite number >= 0");
    weights[size_t(index)] = weight;
  }
  return weights;
}

// ---------------------------------------------------------------------------
// Generator

struct PhantomScratch::Buffers {
  std::vector<Vec3> controls;
  Guide guide;
};
PhantomScratch::PhantomScratch() : buffers(std::make_unique<Buffers>()) {}
PhantomScratch::~PhantomScratch() = default;
PhantomScratch::PhantomScratch(PhantomScratch&&) noexcept = default;
PhantomScratch& PhantomScratch::operator=(PhantomScratch&&) noexcept = default;

struct PhantomGenerator::Tracker {
  TrackerParameters params;
};

PhantomGenerator::PhantomGenerator(const PhantomOptions& options) : options_(options) {
  validatePhantomOptions(options_);
  const double* weights = options_.bundle_weights.empty() ? kWholeBrainWeights.data() : options_.bundle_weights.data();
  double total = 0;
  for (size_t i = 0; i < kPhantomBundleCount; ++i) total += weights[i];
  double running = 0;
  for (size_t i = 0; i < kPhantomBundleCount; ++i) {
    running += weights[i];
    cumulative_weights_[i] = running / total;
  }
  // From the last bundle with a weight on, exactly 1: rounding must never
  // let a uniform draw in [0, 1) select a trailing bundle of weight 0.
  size_t last = kPhantomBundleCount - 1;
  while (last > 0 && weights[last] == 0.0) --last;
  for (size_t i = last; i < kPhantomBundleCount; ++i) cumulative_weights_[i] = 1.0;

  step_ = options_.step_mm;
  min_steps_ = std::max<uint64_t>(1, uint64_t(std::ceil(options_.min_length_mm / step_ - 1e-9)));
  max_steps_ = std::max<uint64_t>(min_steps_, uint64_t(std::floor(options_.max_length_mm / step_ + 1e-9)));

  auto tracker = std::make_shared<Tracker>();
  TrackerParameters& p = tracker->params;
  p.step = step_;
  p.lookahead = kLookaheadMm;
  p.steer = std::min(0.5, step_ / (kLookaheadMm / 4.0));
  p.jitter_sigma = options_.jitter * radians(kJitterDegreesPerTenthMm) * std::sqrt(step_ / 0.1);
  // The tracker turns its exact direction by at most this much; the stored
  // float points then deviate from it by at most kFloatPositionError at each
  // end of a segment, which tilts each stored segment by at most
  // kFloatPositionError / step radians. Two tilts are kept in reserve so
  // that the turn measured between stored points never exceeds the option.
  const double max_turn = radians(options_.max_angle_deg) - 2.02 * kFloatPositionError / step_;
  p.cos_max_turn = std::cos(max_turn);
  p.sin_max_turn = std::sin(max_turn);
  tracker_ = std::move(tracker);
}

PhantomBundle PhantomGenerator::generate(uint64_t index, std::vector<float>& xyz, PhantomScratch& scratch,
                                         unsigned* retries) const {
  PhantomScratch::Buffers& buffers = *scratch.buffers;
  const size_t base = xyz.size();
  PhantomBundle bundle = PhantomBundle::CorpusCallosum;
  for (uint32_t attempt = 0; attempt < kPhantomMaxRetries; ++attempt) {
    if (retries) *retries = attempt;
    Rng rng(streamlineKey(options_.seed, index, attempt));
    const double pick = rng.uniform();
    size_t b = 0;
    while (b + 1 < kPhantomBundleCount && pick >= cumulative_weights_[b]) ++b;
    bundle = PhantomBundle(b);
    fiberControls(bundle, rng, options_.bundle_radius_scale, buffers.controls);
    // Trackers seed anywhere and run both ways, so either end may come first.
    if (rng.next() & 1) std::reverse(buffers.controls.begin(), buffers.controls.end());
    buildGuide(buffers.controls, kGuideSpacingMm, buffers.guide);

    if (buffers.guide.tangents.empty()) continue;  // degenerate guide (a point): cannot be walked
    const double guide_length = buffers.guide.length();
    double span = guide_length, start = 0;
    if (rng.uniform() >= fullSpanProbability(bundle)) {
      span = guide_length * rng.uniform(0.4, 1.0);
      start = rng.uniform() * (guide_length - span);
    }
    const uint64_t steps = std::clamp<uint64_t>(uint64_t(span / step_), min_steps_, max_steps_);
    if (double(steps) * step_ > guide_length) continue;  // this guide cannot give the minimum length
    start = std::min(start, guide_length - double(steps) * step_);

    const size_t points = trackAlongGuide(buffers.guide, start, size_t(steps), tracker_->params, rng, xyz);
    if (points >= min_steps_ + 1) return bundle;
    xyz.resize(base);  // left the ellipsoid too early: try another fiber
  }
  // Only reached when the weights leave no bundle long enough for
  // min_length_mm (with the defaults, attempts fail independently and
  // rarely), but a generator must not fail: a straight anterior-posterior
  // fiber through the centre, which fits the ellipsoid for every allowed
  // minimum length (<= 150 mm < 170 mm).
  if (retries) *retries = kPhantomMaxRetries;
  // Each point is one step from the stored previous one, as in the tracker,
  // so each segment carries one rounding only.
  float y = float(-0.5 * double(min_steps_) * step_);
  for (uint64_t k = 0; k <= min_steps_; ++k) {
    if (k > 0) y = opaqueFloat(double(y) + step_);
    xyz.push_back(0.0f);
    xyz.push_back(y);
    xyz.push_back(0.0f);
  }
  return bundle;
}

void PhantomGenerator::generateRange(uint64_t first, uint64_t count, Tractogram& out, PhantomScratch& scratch) const {
  if (out.per_streamline.empty()) out.per_streamline.push_back({"bundle", 1, "uint8", {}});
  std::vector<float>& bundles = out.per_streamline[0].values;
  out.offsets.reserve(out.offsets.size() + count);
  bundles.reserve(bundles.size() + count);
  for (uint64_t i = 0; i < count; ++i) {
    const PhantomBundle bundle = generate(first + i, out.positions, scratch);
    out.offsets.push_back(out.positions.size() / 3);
    bundles.push_back(float(uint8_t(bundle)));
  }
}

// ---------------------------------------------------------------------------
// Streaming reader

namespace {

class PhantomReader final : public TractogramReader {
 public:
  explicit PhantomReader(const PhantomOptions& options);
  ~PhantomReader() override;
  bool read(Tractogram& chunk, size_t max_points) override;
  uint64_t bytesRead() const override { return bytes_read_; }

 private:
  // A run of consecutive streamlines generated by up to threads_ workers,
  // each into its own part, which are handed out in order.
  struct Batch {
    uint64_t first = 0;
    uint64_t count = 0;
    std::vector<Tractogram> parts;
    std::vector<std::thread> workers;
    std::vector<std::exception_ptr> errors;
    bool launched = false;
    size_t part = 0;        // consumption cursor: part
    size_t streamline = 0;  //   and streamline within it
  };
  void launch(Batch& batch, uint64_t first, uint64_t count);
  void wait(Batch& batch);
  uint64_t batchSize(size_t max_points) const;
  double meanPoints() const;

  PhantomGenerator generator_;
  unsigned threads_;
  std::vector<PhantomScratch> scratch_;  // one per worker slot
  Batch current_, next_;
  uint64_t launched_up_to_ = 0;  // streamlines [0, launched_up_to_) are generated or being generated
  uint64_t generated_points_ = 0, generated_streamlines_ = 0;
  uint64_t bytes_read_ = 0;
};

PhantomReader::PhantomReader(const PhantomOptions& options) : generator_(options) {
  threads_ = options.threads != 0 ? options.threads : std::max(1u, std::thread::hardware_concurrency());
  // Two batches may be in flight at once (the one being consumed is done).
  scratch_.resize(threads_);

  header_.path = "phantom";
  header_.format = "phantom";
  header_.declared_streamlines = int64_t(options.streamlines);
  header_.per_streamline.push_back({"bundle", 1, "uint8", {}});
  // A 1 mm grid whose voxel centres cover the ellipsoid, for formats that
  // need a reference image (trk, trx).
  header_.space.known = true;
  header_.space.dimensions = {int32_t(2 * kPhantomSemiAxesMm[0] + 1), int32_t(2 * kPhantomSemiAxesMm[1] + 1),
                              int32_t(2 * kPhantomSemiAxesMm[2] + 1)};
  header_.space.voxel_sizes = {1, 1, 1};
  header_.space.voxel_to_rasmm = {1, 0, 0, float(-kPhantomSemiAxesMm[0]), 0, 1, 0, float(-kPhantomSemiAxesMm[1]),
                                  0, 0, 1, float(-kPhantomSemiAxesMm[2]), 0, 0, 0, 1};
  header_.space.voxel_order = "RAS";

  const PhantomOptions& o = generator_.options();
  std::string names, weights;
  for (size_t i = 0; i < kPhantomBundleCount; ++i) {
    // Appended piece by piece: GCC 12 at -O3 warns falsely (-Wrestrict) on
    // literal + temporary string.
    if (i) {
      names += ',';
      weights += ',';
    }
    names += kBundleNames[i];
    weights += number(o.bundle_weights.empty() ? kWholeBrainWeights[i] : o.bundle_weights[i]);
  }
  header_.properties = {{"method", "phantom"},
                        {"step_size", number(o.step_mm)},
                        {"max_angle", number(o.max_angle_deg)},
                        {"min_dist", number(o.min_length_mm)},
                        {"max_dist", number(o.max_length_mm)},
                        {"phantom_seed", std::to_string(o.seed)},
                        {"phantom_jitter", number(o.jitter)},
                        {"phantom_bundles", names},
                        {"phantom_bundle_weights", weights},
                        {"phantom_bundle_radius_scale", number(o.bundle_radius_scale)}};
}

PhantomReader::~PhantomReader() {
  for (Batch* batch : {&current_, &next_})
    for (auto& worker : batch->workers)
      if (worker.joinable()) worker.join();
}

double PhantomReader::meanPoints() const {
  if (generated_streamlines_ > 0) return std::max(1.0, double(generated_points_) / double(generated_streamlines_));
  const PhantomOptions& o = generator_.options();
  return std::clamp(90.0, o.min_length_mm, o.max_length_mm) / o.step_mm + 1.0;
}

uint64_t PhantomReader::batchSize(size_t max_points) const {
  // Enough streamlines for one chunk by the running mean of points per
  // streamline (at least 64 k points, so that small chunks still keep the
  // workers busy long enough to pay for starting them).
  const double wanted = double(std::max<size_t>(max_points, size_t(1) << 16)) / meanPoints();
  return std::max<uint64_t>(1, uint64_t(std::ceil(wanted)));
}

void PhantomReader::launch(Batch& batch, uint64_t first, uint64_t count) {
  const unsigned parts = unsigned(std::min<uint64_t>(threads_, count));
  batch.first = first;
  batch.count = count;
  batch.parts.resize(parts);
  batch.errors.assign(parts, nullptr);
  batch.workers.clear();
  batch.part = 0;
  batch.streamline = 0;
  batch.launched = true;
  // Scratch slots: workers of `current_` are always joined before `next_`
  // is launched, so one slot per worker suffices.
  const double points_per_streamline = meanPoints();
  for (unsigned w = 0; w < parts; ++w) {
    const uint64_t begin = first + count * w / parts, end = first + count * (w + 1) / parts;
    // Room for the expected points and a margin, so parts rarely grow: a
    // regrown part costs a copy and fresh page faults (large blocks come
    // from mmap, so every reallocation touches new pages).
    std::vector<float>& positions = batch.parts[w].positions;
    batch.parts[w].clear();
    const size_t expected = size_t(3.0 * points_per_streamline * double(end - begin)) + 3 * 4096;
    if (positions.capacity() < expected) positions.reserve(expected + expected / 4);
    batch.workers.emplace_back([this, &batch, w, begin, end] {
      try {
        generator_.generateRange(begin, end - begin, batch.parts[w], scratch_[w]);
      } catch (...) {
        batch.errors[w] = std::current_exception();
      }
    });
  }
}

void PhantomReader::wait(Batch& batch) {
  for (auto& worker : batch.workers)
    if (worker.joinable()) worker.join();
  batch.workers.clear();
  for (const auto& error : batch.errors)
    if (error) std::rethrow_exception(error);
  for (const auto& part : batch.parts) {
    generated_points_ += part.pointCount();
    generated_streamlines_ += part.streamlineCount();
  }
}

bool PhantomReader::read(Tractogram& chunk, size_t max_points) {
  chunk.clear();
  if (chunk.per_streamline.size() != 1 || chunk.per_streamline[0].name != "bundle")
    chunk.per_streamline = {DataArray{"bundle", 1, "uint8", {}}};
  chunk.per_point.clear();
  const uint64_t total = generator_.options().streamlines;
  max_points = std::max<size_t>(1, max_points);

  while (true) {
    if (!current_.launched || current_.part >= current_.parts.size()) {
      // The current batch is used up: the prefetched one becomes current.
      if (!next_.launched && launched_up_to_ < total) {
        const uint64_t count = std::min(batchSize(max_points), total - launched_up_to_);
        launch(next_, launched_up_to_, count);
        launched_up_to_ += count;
      }
      if (!next_.launched) break;  // all streamlines handed out
      wait(next_);
      std::swap(current_, next_);
      next_.launched = false;
      // Prefetch: generate the following batch while the caller consumes
      // this one (the scratch slots are free: next_'s workers are joined).
      if (launched_up_to_ < total) {
        const uint64_t count = std::min(batchSize(max_points), total - launched_up_to_);
        launch(next_, launched_up_to_, count);
        launched_up_to_ += count;
      }
      continue;
    }
    // Hand out whole streamlines of the current part while they fit.
    const Tractogram& part = current_.parts[current_.part];
    const size_t first = current_.streamline;
    size_t last = first;
    const uint64_t room = max_points - std::min<uint64_t>(max_points, chunk.pointCount());
    const uint64_t part_base = part.offsets[first];
    while (last < part.streamlineCount() &&
           (part.offsets[last + 1] - part_base <= room || (chunk.streamlineCount() == 0 && last == first)))
      ++last;
    if (last > first) {
      const uint64_t chunk_base = chunk.pointCount();
      const uint64_t points = part.offsets[last] - part_base;
      chunk.positions.insert(chunk.positions.end(), part.positions.begin() + ptrdiff_t(3 * part_base),
                             part.positions.begin() + ptrdiff_t(3 * (part_base + points)));
      for (size_t i = first + 1; i <= last; ++i) chunk.offsets.push_back(chunk_base + part.offsets[i] - part_base);
      const auto& bundles = part.per_streamline[0].values;
      chunk.per_streamline[0].values.insert(chunk.per_streamline[0].values.end(),
                                            bundles.begin() + ptrdiff_t(first), bundles.begin() + ptrdiff_t(last));
      bytes_read_ += 12 * points;
      current_.streamline = last;
    }
    if (current_.streamline >= part.streamlineCount()) {
      ++current_.part;
      current_.streamline = 0;
      continue;
    }
    break;  // the chunk is full
  }
  return chunk.streamlineCount() > 0;
}

}  // namespace

std::unique_ptr<TractogramReader> openPhantom(const PhantomOptions& options) {
  return std::make_unique<PhantomReader>(options);
}

}  // namespace fibscope
