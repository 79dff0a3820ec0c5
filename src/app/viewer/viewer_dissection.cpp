#include "app/viewer/viewer_dissection.h"

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <set>

#include "app/open_input.h"
#include "core/error.h"
#include "io/writer.h"
#include "select/filter_run.h"

namespace fibscope {
namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// The criteria as text: equal text, equal kept bits (a mask by its path).
std::string criteriaKey(const FiberFilter& filter) {
  const FilterCriteria& c = filter.criteria();
  std::string key;
  for (const auto* list : {&c.include, &c.exclude, &c.include_ordered}) {
    key += '|';
    for (const Region& r : *list) key += regionSpec(r) + ';';
  }
  char buf[64];
  std::snprintf(buf, sizeof buf, "|%d|%a|%a", int(c.ends_only), double(filter.minLength()), double(filter.maxLength()));
  key += buf;
  for (size_t i = 0; i < c.scalar_ranges.size(); ++i) {
    std::snprintf(buf, sizeof buf, "|%a,%a", double(filter.scalarMin(i)), double(filter.scalarMax(i)));
    key += scalarRangeArray(c.scalar_ranges[i]) + buf;
  }
  return key;
}

// The values of `range` for every fiber of the scene: each file's
// "dps/NAME" section at its entry's fiber base; NaN (dropped) for the
// fibers of a model without that array or component.
std::vector<float> sceneScalarValues(const DissectionScene& scene, uint32_t fibers, const ScalarRange& range) {
  std::vector<float> values(fibers, NAN);
  const std::string section = std::string(kFblSectionDpsPrefix) + range.name;
  for (size_t i = 0; i < scene.files.size(); ++i) {
    const FblFile* file = scene.files[i];
    const FblSection* s = file ? file->find(section) : nullptr;
    if (!s || range.component >= s->components) continue;
    const std::span<const float> data = file->array<float>(*s);
    const uint32_t base = scene.raw ? 0 : scene.layout->entries[i].fiber_base;
    const uint64_t n = std::min<uint64_t>(data.size() / s->components, fibers - base);
    for (uint64_t f = 0; f < n; ++f) values[base + f] = data[f * s->components + range.component];
  }
  return values;
}

std::string sceneKey(const DissectionScene& scene) {
  if (!scene.raw && !scene.layout) return "";
  char buf[96];
  std::string key;
  if (scene.raw) {
    std::snprintf(buf, sizeof buf, "raw:%llx,%llx", static_cast<unsigned long long>(scene.raw->blockAddress()),
                  static_cast<unsigned long long>(scene.raw_lengths));
    return buf;
  }
  for (const SceneEntry& e : scene.layout->entries) {
    std::snprintf(buf, sizeof buf, "%llx,%u,%u;", static_cast<unsigned long long>(e.block), e.fiber_base, e.fibers);
    key += buf;
  }
  return key;
}

// A reader that stops at its next chunk once `cancel` is set (the viewer
// quitting during an export).
class CancellableReader final : public TractogramReader {
 public:
  CancellableReader(std::unique_ptr<TractogramReader> inner, const std::atomic<bool>* cancel)
      : inner_(std::move(inner)), cancel_(cancel) {
    header_ = inner_->header();
  }
  bool read(Tractogram& chunk, size_t max_points) override {
    if (cancel_ && cancel_->load(std::memory_order_relaxed)) fail(header_.path, "export cancelled");
    return inner_->read(chunk, max_points);
  }
  uint64_t bytesRead() const override { return inner_->bytesRead(); }
  const std::vector<std::string>& innerWarnings() const { return inner_->warnings(); }

 private:
  std::unique_ptr<TractogramReader> inner_;
  const std::atomic<bool>* cancel_;
};

// TRX groups of the kept fibers, one per ROI (enabled or not) holding any:
// the fibers with a vertex in it (with ends only, an end), as the filter
// tests them. With tckedit's semantics every kept fiber enters every
// enabled include ROI, so those groups hold the whole file; what they add
// is where the kept fibers pass the other ROIs (disabled ones, a set's
// spare regions).
class GroupingWriter final : public TractogramWriter {
 public:
  GroupingWriter(TractogramWriter& inner, const RoiSet& set) : inner_(inner), set_(set), members_(set.rois.size()) {}
  void write(const Tractogram& chunk) override {
    for (size_t s = 0; s < chunk.streamlineCount(); ++s) {
      const size_t n = chunk.pointsIn(s);
      const float* p = chunk.point(chunk.offsets[s]);
      for (size_t r = 0; r < set_.rois.size(); ++r) {
        bool in = false;
        for (size_t i = 0; i < n && !in; ++i) {
          if (set_.ends_only && i != 0 && i + 1 != n) continue;
          in = regionContains(set_.rois[r].region, p + 3 * i);
        }
        if (in) members_[r].push_back(uint32_t(written_ + s));
      }
    }
    written_ += chunk.streamlineCount();
    inner_.write(chunk);
  }
  void finish() override {}
  // The groups, named after their ROIs (made valid TRX member names, unique).
  std::vector<Group> groups() const {
    std::vector<Group> out;
    std::set<std::string> used;
    for (size_t r = 0; r < set_.rois.size(); ++r) {
      if (members_[r].empty()) continue;
      std::string name = set_.rois[r].name;
      for (char& c : name)
        if (c == '/' || c == '\\' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '.') c = '_';
      if (name.empty()) name = "roi";
      std::string unique = name;
      for (int k = 2; used.count(unique); ++k) unique = name + "_" + std::to_string(k);
      used.insert(unique);
      out.push_back(Group{unique, members_[r]});
    }
    return out;
  }

 private:
  TractogramWriter& inner_;
  const RoiSet& set_;
  std::vector<std::vector<uint32_t>> members_;
  uint64_t written_ = 0;
};

bool isTrxPath(const std::string& path) {
  return path.size() >= 4 && (path.compare(path.size() - 4, 4, ".trx") == 0 || path.back() == '/');
}

}  // namespace

std::vector<DataArray> fblPerStreamlineArrays(const FblFile& file) {
  std::vector<DataArray> out;
  for (const FblSection& s : file.sections())
    if (s.name.starts_with(kFblSectionDpsPrefix) && s.dtype == FblDType::kFloat32)
      out.push_back({s.name.substr(kFblSectionDpsPrefix.size()), s.components, "float32", {}});
  return out;
}

ViewerDissection::~ViewerDissection() {
  if (cancel_export_) cancel_export_->store(true);
  if (export_.valid()) export_.wait();
}

GpuFiberFilter& ViewerDissection::filter(std::unique_ptr<GpuFiberFilter>& f) {
  if (!f) f = std::make_unique<GpuFiberFilter>(context_);
  return *f;
}

void ViewerDissection::evaluate(DissectionState& state, const DissectionScene& scene, bool now) {
  DissectionStats& stats = state.stats;
  const FilterCriteria criteria = dissectionCriteria(state);
  const uint32_t fibers = scene.raw ? scene.raw->streamlineCount() : (scene.layout ? scene.layout->fibers : 0);
  const std::string skey = sceneKey(scene);
  if (skey != arrays_key_) {
    // The panel's list: every model's arrays, each component's range of values.
    stats.scalar_arrays.clear();
    for (const FblFile* file : scene.files) {
      if (!file) continue;
      for (const DataArray& a : fblPerStreamlineArrays(*file)) {
        auto it = std::find_if(stats.scalar_arrays.begin(), stats.scalar_arrays.end(),
                               [&](const DissectionStats::ScalarArray& x) { return x.name == a.name; });
        if (it == stats.scalar_arrays.end()) it = stats.scalar_arrays.insert(stats.scalar_arrays.end(), {a.name, 0, {}, {}});
        it->components = std::max(it->components, a.components);
        it->lo.resize(it->components, INFINITY);
        it->hi.resize(it->components, -INFINITY);
        const std::span<const float> data = file->array<float>(*file->find(std::string(kFblSectionDpsPrefix) + a.name));
        for (size_t i = 0; i < data.size(); ++i) {
          const float v = data[i];
          if (!std::isfinite(v)) continue;
          float& lo = it->lo[i % a.components];
          float& hi = it->hi[i % a.components];
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      }
    }
    arrays_key_ = skey;
  }
  stats.active = !criteria.empty();
  if (!stats.active) {
    // Nothing to filter: no GPU work, every fiber kept.
    stats.evaluated = true;
    stats.kept = stats.fibers = fibers;
    stats.error.clear();
    criteria_key_ = scene_key_ = pending_key_ = {};
    failed_ = false;
    return;
  }
  std::optional<FiberFilter> filter_criteria;
  try {
    filter_criteria.emplace(criteria, scene.step_size_mm);
  } catch (const Error& e) {  // lengths the edits check already; kept for sets loaded with odd limits
    stats.error = e.what();
    stats.evaluated = true;
    stats.kept = stats.fibers = fibers;
    failed_ = true;
    criteria_key_.clear();
    return;
  }
  const std::string ckey = criteriaKey(*filter_criteria);
  if (skey == scene_key_ && ckey == criteria_key_) {
    stats.evaluated = true;
    return;
  }
  if (skey == scene_key_ && !now && last_update_ms_ > kSlowUpdateMs) {
    // The criteria alone changed after a slow update: wait for them to settle.
    if (ckey != pending_key_) {
      pending_key_ = ckey;
      pending_since_ = Clock::now();
    }
    if (msSince(pending_since_) < kSettleMs) {
      stats.evaluated = false;
      return;
    }
  }
  // The pipelines first (once): the update's time is the filter's alone.
  try {
    filter(scene.raw ? raw_ : fiblets_);
  } catch (const Error& e) {
    stats.error = e.what();
    stats.evaluated = true;
    stats.kept = stats.fibers = fibers;
    failed_ = true;
    scene_key_ = skey;  // not retried until something changes
    criteria_key_ = ckey;
    return;
  }
  const auto start = Clock::now();
  scene_key_ = skey;
  criteria_key_ = ckey;
  pending_key_.clear();
  raw_scene_ = scene.raw != nullptr;
  try {
    // The ranges' values, read again only when the scene or the ranges' arrays change.
    std::string values_key = skey;
    for (const ScalarRange& r : criteria.scalar_ranges) values_key += "|" + scalarRangeArray(r);
    if (values_key != scalars_key_) {
      scalars_.clear();
      for (const ScalarRange& r : criteria.scalar_ranges) scalars_.push_back(sceneScalarValues(scene, fibers, r));
      scalars_key_ = values_key;
    }
    if (scene.raw) {
      filter(raw_).update(*filter_criteria,
                          FilterRawSource{scene.raw->blockAddress(), scene.raw->streamlineCount(),
                                          scene.raw->pointCount(), scene.raw_lengths},
                          scalars_);
    } else {
      std::vector<FilterFibletSource> sources;
      for (const SceneEntry& e : scene.layout->entries)
        sources.push_back({e.block, e.fiblets, e.fibers, e.fiber_base, e.dataset->fiberLength().address});
      filter(fiblets_).update(*filter_criteria, sources, scene.layout->fibers, scalars_);
    }
    failed_ = false;
    stats.error.clear();
    const GpuFiberFilter& f = scene.raw ? *raw_ : *fiblets_;
    stats.kept = f.keptCount();
  } catch (const Error& e) {
    // Criteria the GPU filter cannot take: everything drawn, the reason
    // shown, not retried until the criteria or the scene change.
    failed_ = true;
    stats.error = e.what();
    stats.kept = fibers;
    if (fiblets_) fiblets_->clear();
    if (raw_) raw_->clear();
  }
  stats.fibers = fibers;
  stats.evaluated = true;
  last_update_ms_ = msSince(start);
  stats.update_ms = last_update_ms_;
}

bool ViewerDissection::apply(const DissectionState& state, GpuScene& scene, bool baseline) const {
  if (!state.stats.active || failed_ || scene_key_.empty() || baseline != raw_scene_) return false;
  const GpuFiberFilter* f = baseline ? raw_.get() : fiblets_.get();
  if (!f) return false;
  if (state.dim_dropped) {
    // (Nothing kept: the words are passed anyway, an empty selection
    // would dim nothing.)
    scene.selection_bits = f->keptBits();
    return true;
  }
  scene.kept_bits = f->keptBits();
  scene.kept_point_bits = f->keptPointBits();
  return false;
}

std::optional<std::vector<uint32_t>> ViewerDissection::keptSceneFibers(const DissectionState& state) const {
  if (!state.stats.active || failed_ || scene_key_.empty() || raw_scene_ || !fiblets_) return std::nullopt;
  return fiblets_->keptFibers();
}

void ViewerDissection::startExport(const DissectionState& state, const DissectionExportSource& source,
                                   const std::string& path) {
  if (exporting()) throw Error(path + ": an export is running already");
  cancel_export_ = std::make_shared<std::atomic<bool>>(false);
  export_ = std::async(std::launch::async, [set = state.set, source, path, cancel = cancel_export_] {
    return exportKeptFibers(set, source, path, cancel.get());
  });
}

std::optional<DissectionExportResult> ViewerDissection::pollExport() {
  if (!export_.valid() || export_.wait_for(std::chrono::seconds(0)) != std::future_status::ready) return std::nullopt;
  std::future<DissectionExportResult> done = std::move(export_);
  return done.get();  // rethrows the export's Error
}

DissectionExportResult exportKeptFibers(const RoiSet& set, const DissectionExportSource& source,
                                        const std::string& path, const std::atomic<bool>* cancel) {
  const auto start = Clock::now();
  if (path.empty()) throw Error("export: no output path given");
  std::unique_ptr<TractogramReader> inner = source.path.empty() ? openPhantom(source.phantom) : openInput(source.path);
  CancellableReader reader(std::move(inner), cancel);
  // What `fibscope filter IN OUT` does with the same criteria.
  const FiberFilter filter(filterCriteria(set), headerStepSize(reader.header()));
  WriterOptions options;
  options.overwrite = true;  // the panel's button writes the same file again
  std::unique_ptr<TractogramWriter> writer = createTractogramWriter(path, reader.header(), options);
  DissectionExportResult result;
  if (isTrxPath(path)) {
    GroupingWriter grouping(*writer, set);
    const FilterReport report = runFilter(reader, grouping, filter);
    std::vector<Group> groups = grouping.groups();
    result.groups = groups.size();
    writer->setGroups(std::move(groups));
    result.kept = report.kept;
    result.streamlines = report.streamlines;
  } else {
    const FilterReport report = runFilter(reader, *writer, filter);
    result.kept = report.kept;
    result.streamlines = report.streamlines;
  }
  writer->finish();
  result.path = path;
  result.model = source.model;
  result.warnings = reader.innerWarnings();
  for (const std::string& w : writer->warnings()) result.warnings.push_back(w);
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return result;
}

}  // namespace fibscope
