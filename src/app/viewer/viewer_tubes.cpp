#include "app/viewer/viewer_tubes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "gpu/buffer.h"
#include "render/fiber_selection.h"

namespace fibscope {
namespace {

// Appends the values of `fibers` in `file`'s array `name` to `out`'s
// array "radius": its per-fiber "dps/NAME" section (one float32 per fiber)
// to out.per_streamline, else its per-point "dpv/NAME" section (one float32
// per point, found through "fiber_first_point") to out.per_point, whose
// last fibers.size() streamlines must be those fibers as decoded (their
// point counts are checked against the table). Throws Error naming the file
// when it has neither, or the table disagrees.
void appendFiberValues(const FblFile& file, const std::string& name, const std::vector<uint32_t>& fibers,
                       Tractogram& out) {
  const uint64_t fiber_count = file.header().fiber_count;
  if (const FblSection* s = file.find(std::string(kFblSectionDpsPrefix) + name)) {
    if (s->dtype != FblDType::kFloat32 || s->components != 1 || s->element_count != fiber_count)
      throw Error("tubes: " + file.path() + ": the per-fiber array '" + name + "' is not one float per fiber");
    const auto values = file.array<float>(*s);
    if (out.per_streamline.empty()) out.per_streamline.push_back(DataArray{"radius", 1, "float32", {}});
    for (const uint32_t f : fibers) out.per_streamline[0].values.push_back(values[f]);
    return;
  }
  const FblSection* s = file.find(std::string(kFblSectionDpvPrefix) + name);
  const FblSection* first = file.find(kFblSectionFiberFirstPoint);
  if (!s) throw Error("tubes: " + file.path() + " has no per-fiber or per-point array '" + name + "'");
  if (s->dtype != FblDType::kFloat32 || s->components != 1 || !first || first->dtype != FblDType::kUint64 ||
      first->components != 1 || first->element_count != fiber_count + 1)
    throw Error("tubes: " + file.path() + ": the per-point array '" + name +
                "' is not one float per point with its fiber_first_point table");
  const auto values = file.array<float>(*s);
  const auto starts = file.array<uint64_t>(*first);
  if (out.per_point.empty()) out.per_point.push_back(DataArray{"radius", 1, "float32", {}});
  std::vector<float>& dst = out.per_point[0].values;
  const size_t base = out.streamlineCount() - fibers.size();
  for (size_t i = 0; i < fibers.size(); ++i) {
    const uint64_t a = starts[fibers[i]], b = starts[fibers[i] + 1], n = out.pointsIn(base + i);
    if (b < a || b - a != n || b > values.size())
      throw Error("tubes: " + file.path() + ": section 'fiber_first_point': fiber " + std::to_string(fibers[i]) +
                  " spans points " + std::to_string(a) + ".." + std::to_string(b) + ", but it decodes to " +
                  std::to_string(n) + " points");
    dst.insert(dst.end(), values.begin() + ptrdiff_t(a), values.begin() + ptrdiff_t(b));
  }
}

// The radius of the values appendFiberValues collected (per fiber, or per
// point when the array is one): their finite range mapped onto the
// panel's radii.
TubeRadius dataRadius(const Tractogram& fibers, const std::string& from, float radius_min, float radius_max) {
  if (!fibers.per_streamline.empty() && !fibers.per_point.empty())
    throw Error("tubes: '" + from + "' is a per-fiber array in one model and a per-point one in another");
  TubeRadius r;
  const bool per_point = !fibers.per_point.empty();
  r.source = per_point ? TubeRadius::Source::PerPoint : TubeRadius::Source::PerFiber;
  r.array = "radius";
  r.radius_min = radius_min;
  r.radius_max = radius_max;
  if (!(r.radius_min > 0.0f) || !(r.radius_max >= r.radius_min))
    throw Error("tubes: the radius range must be > 0 mm and ordered");
  fitRadiusDataRange(r, per_point ? fibers.per_point.at(0).values : fibers.per_streamline.at(0).values);
  return r;
}

// The request's parts of the key (what the worker builds beside the
// model): the octree's, the distance field's.
std::string requestSvoText(const ViewerTubeRequest& r) {
  return "|svo " + std::to_string(int(r.svo)) + " " + std::to_string(r.voxel_mm);
}
std::string requestFieldText(const ViewerTubeRequest& r) {
  return "|df " + std::to_string(r.distance_field) + " " + std::to_string(r.df_voxel_mm);
}

double secondsSince(std::chrono::steady_clock::time_point t) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count();
}

}  // namespace

void ViewerTubes::Shared::report(const ProgressSnapshot& s) {
  std::lock_guard lock(mutex);
  progress = s;
}

void ViewerTubes::Shared::throwIfCancelled() const {
  if (cancel) throw Error("tubes: the build was cancelled");
}

void ViewerTubes::Shared::phase(const char* label) {
  throwIfCancelled();
  report(ProgressSnapshot{label});
}

ViewerTubes::ViewerTubes(const gpu::VulkanContext& context, std::string device_name,
                         std::shared_ptr<gpu::DebugLog> validation_log, std::string cache_dir)
    : context_(context),
      device_name_(std::move(device_name)),
      validation_log_(std::move(validation_log)),
      cache_(std::move(cache_dir)) {}

ViewerTubes::~ViewerTubes() {
  shared_->cancel = true;
  if (build_.valid()) build_.wait();
  clear();
  worker_context_.reset();
}

void ViewerTubes::clearField() {
  destroyDistanceField(context_, field_);
  field_ = {};
}

void ViewerTubes::clear() {
  clearField();
  destroySvo(context_, svo_);
  svo_ = {};
  destroyTubes(context_, tubes_);
  tubes_ = {};
  spline_ = {};
  drawn_model_.reset();
  drawn_model_key_.clear();
  drawn_svo_key_.clear();
}

std::shared_ptr<const ViewerTubes::ModelPart> ViewerTubes::buildModel(const Job& job) {
  const ModelOptions& o = job.options;
  const bool svo = job.request.svo != TubesInfo::Svo::None;
  auto part = std::make_shared<ModelPart>();
  const auto t0 = std::chrono::steady_clock::now();
  Tractogram fibers;
  std::vector<uint32_t> scene_ids;
  size_t total = 0;
  for (const ViewerTubeSource& source : job.sources) total += source.fibers.size();
  {
    Progress decoding("decoding fibers", double(total), "fibers", false, progressSink());
    for (const ViewerTubeSource& source : job.sources) {
      if (source.fibers.empty()) continue;
      if (!source.fbl) throw Error("tubes: a model's .fbl is not in reach");
      if (svo && cache_.enabled()) part->model_texts.push_back(svoCacheModelText(*source.fbl, source.fibers));
      // In chunks of ~1 M points, each appended once (no whole copy).
      size_t next = 0;
      decodeFibers(*source.fbl, source.fibers, size_t(1) << 20, [&](const Tractogram& chunk) {
        shared_->throwIfCancelled();
        for (size_t i = 0; i < chunk.streamlineCount(); ++i, ++next) {
          fibers.addStreamline(chunk.point(chunk.offsets[i]), chunk.pointsIn(i));
          scene_ids.push_back(source.fiber_base + source.fibers[next]);
        }
        decoding.add(double(chunk.streamlineCount()));
      });
      if (!o.radius_from.empty()) appendFiberValues(*source.fbl, o.radius_from, source.fibers, fibers);
    }
    decoding.finish();
  }
  shared_->throwIfCancelled();
  TubeBuildOptions options;
  options.radius.radius = o.radius_mm;
  // The octree from the fibers' own points, as render's --pipeline svo-*.
  options.resample_tolerance = svo ? 0.0f : o.tolerance_mm;
  if (!o.radius_from.empty()) options.radius = dataRadius(fibers, o.radius_from, o.radius_min, o.radius_max);
  const TubeRadius& r = options.radius;
  part->radius_text = o.radius_from.empty()
                          ? "constant " + std::to_string(r.radius)
                          : "from " + o.radius_from + " " + std::to_string(r.radius_min) + "," +
                                std::to_string(r.radius_max) + " data " + std::to_string(r.data_min) + "," +
                                std::to_string(r.data_max);
  shared_->phase("tube model");
  part->model = buildTubes(fibers, options, &part->stats);
  // buildTubes numbers fibers by their index in `fibers` (the octree's
  // lists index segments, not fibers: the tree does not depend on the
  // scene's numbering).
  for (TubeModel::Tube& t : part->model.tubes) t.fiber = scene_ids[t.fiber];
  for (shader::TubeSegment& s : part->model.segments) s.fiber = scene_ids[s.fiber];
  part->seconds = secondsSince(t0);
  return part;
}

void ViewerTubes::buildOnDevice(const Job& job, Built& b) {
  const ViewerTubeRequest& r = job.request;
  const TubeModel& model = b.model->model;
  const bool svo = r.svo != TubesInfo::Svo::None && !b.svo_kept;
  std::optional<SvoCacheKey> svo_key;
  if (svo && cache_.enabled())
    svo_key = svoCacheKey(b.model->model_texts, b.model->radius_text, 0.0f, r.voxel_mm,
                          r.svo == TubesInfo::Svo::Curved);
  if (svo && svo_key) {
    shared_->phase("reading the octree cache");
    const auto t0 = std::chrono::steady_clock::now();
    b.tree = cache_.lookup(*svo_key, b.warnings, model.segments.size());
    if (b.tree) {
      b.svo_from_cache = true;
      b.svo_seconds = secondsSince(t0);
      if (!r.distance_field) return;  // no device work left
    }
  }
  if (!worker_context_) {
    shared_->phase("starting the device");
    gpu::ContextOptions options;
    options.device_name = device_name_;
    options.instance.validation = validation_log_ != nullptr;
    options.instance.log = validation_log_;
    worker_context_ = std::make_unique<gpu::VulkanContext>(options);
  }
  const gpu::VulkanContext& context = *worker_context_;
  GpuTubes tubes = uploadTubes(context, model);
  try {
    if (svo && !b.tree) {
      SvoGpuBuildOptions options;
      options.progress_sink = progressSink();
      options.cancel = &shared_->cancel;
      // A voxel from the data is coarsened until the octree fits the device.
      const SvoGrid grid =
          chooseSvoGrid(model, r.voxel_mm, r.svo == TubesInfo::Svo::Curved, svoMemoryLimit(context, options));
      const auto t0 = std::chrono::steady_clock::now();
      b.tree = buildSvoGpu(context, model, tubes, grid, options, &b.svo_stats);
      b.svo_seconds = secondsSince(t0);
      if (svo_key) {
        shared_->phase("writing the octree cache");
        cache_.store(*svo_key, *b.tree, b.warnings);
      }
    }
    if (r.distance_field) {
      shared_->phase("distance field");
      b.field_grid = chooseDistanceFieldGrid(model, r.df_voxel_mm);
      GpuDistanceField field = buildDistanceFieldGpu(context, tubes, b.field_grid);
      b.field_seconds = field.build_s;
      try {
        b.field = downloadDistanceField(context, field);
      } catch (...) {
        destroyDistanceField(context, field);
        throw;
      }
      destroyDistanceField(context, field);
    }
  } catch (...) {
    destroyTubes(context, tubes);
    throw;
  }
  destroyTubes(context, tubes);
}

void ViewerTubes::start(Job job) {
  {
    std::lock_guard lock(shared_->mutex);
    shared_->progress.reset();
  }
  // What the drawn tubes already have (the builds before this one are
  // uploaded: one build at a time).
  if (drawn_model_ && job.model_key == drawn_model_key_) {
    job.model = drawn_model_;
    job.keep_svo = job.request.svo != TubesInfo::Svo::None && job.svo_key == drawn_svo_key_ && svo_.nodes.buffer;
  }
  // Builds never overlap (one future at a time), so the worker's context
  // and the cache are used by one thread at a time.
  build_ = std::async(std::launch::async, [this, job = std::move(job)]() {
    Built b;
    b.key = job.key;
    b.model_key = job.model_key;
    b.svo_key = job.svo_key;
    try {
      b.model_kept = job.model != nullptr;
      b.svo_kept = job.keep_svo;
      b.model = job.model ? job.model : buildModel(job);
      if ((job.request.svo != TubesInfo::Svo::None && !b.svo_kept) || job.request.distance_field)
        buildOnDevice(job, b);
    } catch (const Error& e) {
      b.error = e.what();
    }
    return b;
  });
}

void ViewerTubes::upload(Built& built, TubesInfo& info) {
  const bool keep_model = built.error.empty() && built.model_kept;
  const bool keep_svo = keep_model && built.svo_kept;
  if (!keep_model) {
    clear();
    info.fibers = info.nodes = info.points = info.segments = info.bytes = 0;
    info.build_seconds = 0;
  }
  if (!keep_svo) {
    destroySvo(context_, svo_);
    svo_ = {};
    info.svo_leaves = info.svo_nodes_bytes = info.svo_decoration_bytes = 0;
    info.svo_side = 0;
    info.svo_voxel = 0;
    info.svo_from_cache = false;
    info.svo_seconds = 0;
  }
  info.svo_kept = keep_svo;
  clearField();
  info.df_bytes = 0;
  info.df_voxel = 0;
  info.df_seconds = 0;
  info.message = built.error;
  if (!built.error.empty()) return;
  try {
    if (!keep_model) tubes_ = uploadTubes(context_, built.model->model);
    spline_ = {};
    if (built.tree) {
      svo_ = uploadSvo(context_, *built.tree);
    } else if (!keep_svo) {
      spline_ = tubes_;  // a view: the tube stage draws them
    }
    if (!built.field.empty()) {
      field_.grid = built.field_grid;
      field_.build_s = built.field_seconds;
      field_.values = gpu::createBuffer(context_, built.field.size() * sizeof(float), gpu::MemoryUse::DeviceLocal);
      gpu::uploadToBuffer(context_, field_.values, built.field.data(), built.field.size() * sizeof(float));
    }
  } catch (const Error& e) {
    clear();
    info.message = e.what();
    return;
  }
  drawn_model_ = built.model;
  drawn_model_key_ = built.model_key;
  drawn_svo_key_ = svo_.nodes.buffer ? built.svo_key : std::string();
  if (!keep_model) {
    const TubeBuildStats& stats = built.model->stats;
    info.fibers = stats.tubes;
    info.nodes = stats.nodes;
    info.points = stats.input_points;
    info.segments = tubes_.segment_count;
    info.bytes = tubes_.nodes.size + tubes_.segments.size;
    info.build_seconds = built.model->seconds;
  }
  if (built.tree) {
    info.svo_leaves = built.tree->leaves;
    info.svo_nodes_bytes = built.tree->nodeBytes();
    info.svo_decoration_bytes = built.tree->decorationBytes();
    info.svo_side = built.tree->grid.side();
    info.svo_voxel = built.tree->grid.voxel;
    info.svo_from_cache = built.svo_from_cache;
    info.svo_seconds = built.svo_seconds;
  }
  if (!built.field.empty()) {
    info.df_bytes = built.field_grid.bytes();
    info.df_voxel = built.field_grid.voxel;
    info.df_seconds = built.field_seconds;
  }
}

bool ViewerTubes::update(const std::string& tubes_key, const std::function<std::vector<ViewerTubeSource>()>& sources,
                         const ViewerTubeRequest& request, TubesInfo& info, std::vector<std::string>* warnings) {
  bool changed = false;
  const bool svo = request.svo != TubesInfo::Svo::None;
  // The key's parts: the model (its fibers from the octree's own points
  // or resampled), the octree, the field.
  const std::string model_key = tubes_key.empty() ? std::string() : tubes_key + (svo ? "|own points" : "|resampled");
  const std::string svo_key = model_key.empty() ? std::string() : model_key + requestSvoText(request);
  const std::string key = svo_key.empty() ? std::string() : svo_key + requestFieldText(request);
  if (key != wanted_key_) {
    wanted_key_ = key;
    Job job;
    job.key = key;
    job.model_key = model_key;
    job.svo_key = svo_key;
    job.request = request;
    job.options = {info.radius_mm, info.radius_min, info.radius_max, info.tolerance_mm, info.radius_from};
    info.message.clear();
    size_t fibers = 0;
    try {
      if (svo && !(request.voxel_mm >= 0.0f && std::isfinite(request.voxel_mm)))
        throw Error("tubes: the octree's voxel must be > 0 mm (or 0: from the data)");
      if (!(info.radius_mm > 0.0f)) throw Error("tubes: the radius must be > 0 mm");
      if (!key.empty()) job.sources = sources();
      for (const ViewerTubeSource& source : job.sources) fibers += source.fibers.size();
    } catch (const Error& e) {
      fibers = 0;
      info.message = e.what();
    }
    if (fibers == 0) {
      // Nothing to build: no tubes, at once (a running build is discarded).
      pending_.reset();
      const bool had = tubes_.segment_count > 0;
      clear();
      info.fibers = info.nodes = info.points = info.segments = info.bytes = 0;
      info.svo_leaves = 0;
      info.df_bytes = 0;
      if (info.message.empty() && info.wanted()) info.message = "no fibers to show as tubes";
      changed = had;
    } else if (build_.valid()) {
      pending_ = std::move(job);
    } else {
      start(std::move(job));
    }
  }
  if (build_.valid() && build_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
    Built built = build_.get();
    if (warnings) warnings->insert(warnings->end(), built.warnings.begin(), built.warnings.end());
    // What the build kept must still be drawn (tubes switched off and on
    // again while it ran clear them): else it is stale, and the request is
    // made again, in full, unless a newer one waits.
    const bool kept_drawn = (!built.model_kept || built.model == drawn_model_) &&
                            (!built.svo_kept || (svo_.nodes.buffer && built.svo_key == drawn_svo_key_));
    if (built.key == wanted_key_ && kept_drawn) {
      upload(built, info);
      changed = true;
    } else if (built.key == wanted_key_ && !pending_) {
      wanted_key_.clear();
    }
    if (pending_) {
      start(std::move(*pending_));
      pending_.reset();
    }
  }
  info.building = build_.valid();
  if (info.building) {
    info.message.clear();
    std::lock_guard lock(shared_->mutex);
    info.progress = shared_->progress;
  } else {
    info.progress.reset();
  }
  return changed;
}

}  // namespace fibscope
