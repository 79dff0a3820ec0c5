#include "app/viewer/viewer_tubes.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include "core/error.h"
#include "render/fiber_selection.h"

namespace fibscope {
namespace {

// Appends the values of `fibers` in `file`'s per-fiber array `name` (its
// "dps/NAME" section, one float32 per fiber) to `out`'s per-streamline
// array "radius". Throws Error naming the file when it has no such array.
void appendFiberValues(const FblFile& file, const std::string& name, const std::vector<uint32_t>& fibers,
                       Tractogram& out) {
  const FblSection* s = file.find(std::string(kFblSectionDpsPrefix) + name);
  if (!s || s->dtype != FblDType::kFloat32 || s->components != 1 || s->element_count != file.header().fiber_count)
    throw Error("tubes: " + file.path() + " has no per-fiber array '" + name + "' of one float per fiber");
  const auto values = file.array<float>(*s);
  if (out.per_streamline.empty()) out.per_streamline.push_back(DataArray{"radius", 1, "float32", {}});
  for (const uint32_t f : fibers) out.per_streamline[0].values.push_back(values[f]);
}

// The radius of the per-fiber values appendFiberValues collected: their
// finite range mapped onto the panel's radii.
TubeRadius dataRadius(const Tractogram& fibers, const TubesInfo& info) {
  TubeRadius r;
  r.source = TubeRadius::Source::PerFiber;
  r.array = "radius";
  r.radius_min = info.radius_min;
  r.radius_max = info.radius_max;
  if (!(r.radius_min > 0.0f) || !(r.radius_max >= r.radius_min))
    throw Error("tubes: the radius range must be > 0 mm and ordered");
  fitRadiusDataRange(r, fibers.per_streamline.at(0).values);
  return r;
}

}  // namespace

ViewerTubes::~ViewerTubes() {
  if (build_.valid()) build_.wait();
  destroyTubes(context_, tubes_);
}

void ViewerTubes::start(Job job) {
  build_ = std::async(std::launch::async, [job = std::move(job)]() {
    Built b;
    b.key = job.key;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      b.model = buildTubes(job.fibers, job.options, &b.stats);
      // buildTubes numbers fibers by their index in job.fibers.
      for (TubeModel::Tube& t : b.model.tubes) t.fiber = job.scene_ids[t.fiber];
      for (shader::TubeSegment& s : b.model.segments) s.fiber = job.scene_ids[s.fiber];
    } catch (const Error& e) {
      b.error = e.what();
    }
    b.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return b;
  });
}

void ViewerTubes::upload(Built& built, TubesInfo& info) {
  destroyTubes(context_, tubes_);
  tubes_ = {};
  info.fibers = info.nodes = info.points = info.segments = info.bytes = 0;
  info.build_seconds = built.seconds;
  info.message = built.error;
  if (!built.error.empty()) return;
  try {
    tubes_ = uploadTubes(context_, built.model);
  } catch (const Error& e) {
    info.message = e.what();
    return;
  }
  info.fibers = built.stats.tubes;
  info.nodes = built.stats.nodes;
  info.points = built.stats.input_points;
  info.segments = tubes_.segment_count;
  info.bytes = tubes_.nodes.size + tubes_.segments.size;
}

bool ViewerTubes::update(const std::string& key, const std::function<std::vector<ViewerTubeSource>()>& sources,
                         TubesInfo& info) {
  bool changed = false;
  if (key != wanted_key_) {
    wanted_key_ = key;
    Job job;
    job.key = key;
    job.options.radius.radius = info.radius_mm;
    job.options.resample_tolerance = info.tolerance_mm;
    try {
      // The .fbl files are the models' own: read now, while they are
      // loaded (a model may close before the worker would read it).
      for (const ViewerTubeSource& source : sources()) {
        if (source.fibers.empty()) continue;
        if (!source.fbl) throw Error("tubes: a model's .fbl is not in reach");
        // In chunks of ~1 M points, each appended once (no whole copy).
        size_t next = 0;
        decodeFibers(*source.fbl, source.fibers, size_t(1) << 20, [&](const Tractogram& chunk) {
          for (size_t i = 0; i < chunk.streamlineCount(); ++i, ++next) {
            job.fibers.addStreamline(chunk.point(chunk.offsets[i]), chunk.pointsIn(i));
            job.scene_ids.push_back(source.fiber_base + source.fibers[next]);
          }
        });
        if (!info.radius_from.empty()) appendFiberValues(*source.fbl, info.radius_from, source.fibers, job.fibers);
      }
      if (!(info.radius_mm > 0.0f)) throw Error("tubes: the radius must be > 0 mm");
      if (!info.radius_from.empty()) job.options.radius = dataRadius(job.fibers, info);
    } catch (const Error& e) {
      job.fibers = {};
      job.scene_ids.clear();
      info.message = e.what();
    }
    if (job.scene_ids.empty()) {
      // Nothing to build: no tubes, at once (a running build is discarded).
      pending_.reset();
      const bool had = tubes_.segment_count > 0;
      destroyTubes(context_, tubes_);
      tubes_ = {};
      info.fibers = info.nodes = info.points = info.segments = info.bytes = 0;
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
    if (built.key == wanted_key_) {
      upload(built, info);
      changed = true;
    }
    if (pending_) {
      start(std::move(*pending_));
      pending_.reset();
    }
  }
  info.building = build_.valid();
  if (info.building) info.message.clear();
  return changed;
}

}  // namespace fibscope
