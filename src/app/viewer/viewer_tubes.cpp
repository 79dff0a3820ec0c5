#include "app/viewer/viewer_tubes.h"

#include <chrono>
#include <utility>

#include "core/error.h"
#include "render/fiber_selection.h"

namespace fibscope {

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
        const Tractogram t = decodeFibers(*source.fbl, source.fibers);
        for (size_t i = 0; i < t.streamlineCount(); ++i) {
          job.fibers.addStreamline(t.point(t.offsets[i]), t.pointsIn(i));
          job.scene_ids.push_back(source.fiber_base + source.fibers[i]);
        }
      }
      if (!(info.radius_mm > 0.0f)) throw Error("tubes: the radius must be > 0 mm");
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
