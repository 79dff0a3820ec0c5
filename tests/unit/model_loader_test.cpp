// The viewer's model loader (no GPU): loads through the cache on a worker
// thread, errors as one line, bounds and sample, progress, cancellation.
#include "app/model_loader.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <thread>

#include <gtest/gtest.h>

#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"
#include "test_support.h"

namespace fibscope {
namespace {

using test::TempDir;

std::string writePhantomTck(const TempDir& dir, const std::string& name, uint64_t streamlines) {
  return test::writePhantomTck(dir, name, streamlines, 5);
}

ModelLoaderOptions optionsIn(const TempDir& dir) {
  ModelLoaderOptions options;
  options.cache_dir = dir.file("cache");
  options.phantom_streamlines = 200;
  return options;
}

// The event of job `id`; events of other jobs that finish first are kept
// for their own waitFor.
LoadEvent waitFor(ModelLoader& loader, uint64_t id) {
  static std::vector<LoadEvent> early;
  for (auto it = early.begin(); it != early.end(); ++it) {
    if (it->id != id) continue;
    LoadEvent event = std::move(*it);
    early.erase(it);
    return event;
  }
  for (;;) {
    std::optional<LoadEvent> event = loader.wait(60.0);
    if (!event) {
      ADD_FAILURE() << "job " << id << " did not finish";
      return {};
    }
    if (event->id == id) return std::move(*event);
    early.push_back(std::move(*event));
  }
}

bool inside(const Bounds& b, const Vec3d& p, double tolerance) {
  for (int c = 0; c < 3; ++c)
    if (p[c] < b.min[c] - tolerance || p[c] > b.max[c] + tolerance) return false;
  return true;
}

TEST(ModelLoader, aTckLoadsWithTheFilesCountsBoundsAndSample) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "brain.tck", 300);
  const Tractogram direct = readTractogram(tck);
  ModelLoader loader(optionsIn(dir));
  const LoadEvent event = waitFor(loader, loader.request(tck));
  ASSERT_TRUE(event.ok()) << event.error;
  const ModelData& m = *event.model;
  EXPECT_EQ(m.name, "brain.tck");
  EXPECT_EQ(m.source_path, tck);
  EXPECT_EQ(m.streamlines, direct.streamlineCount());
  EXPECT_EQ(m.points, direct.pointCount());
  EXPECT_EQ(m.segments, direct.pointCount() - direct.streamlineCount());
  EXPECT_EQ(m.fbl.header().fiber_count, direct.streamlineCount());
  EXPECT_NEAR(m.step_mm, 0.1, 0.001);
  EXPECT_EQ(m.input_bytes, std::filesystem::file_size(tck));
  EXPECT_EQ(m.fbl_bytes, m.fbl.fileBytes());
  EXPECT_GT(m.compressionRatio(), 3.0);
  EXPECT_FALSE(m.from_cache);
  EXPECT_GT(m.seconds, 0.0);

  // The box: every point inside, and each face within one step of the
  // file's own box (the decoded points are within microns of the originals).
  const Bounds exact = tractogramBounds(direct);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(m.bounds.min[c], exact.min[c], m.step_mm) << c;
    EXPECT_NEAR(m.bounds.max[c], exact.max[c], m.step_mm) << c;
  }
  for (size_t i = 0; i < direct.pointCount(); ++i) {
    const float* p = direct.point(i);
    ASSERT_TRUE(inside(m.bounds, {p[0], p[1], p[2]}, 0.01)) << "point " << i;
  }
  EXPECT_GE(m.sample.size(), 4096u);
  EXPECT_LE(m.sample.size(), 2 * 4096u);
  for (const Vec3d& p : m.sample) ASSERT_TRUE(inside(m.bounds, p, 1e-9));
}

TEST(ModelLoader, theSecondRequestOfAFileComesFromTheCacheAndIsFaster) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "brain.tck", 600);
  ModelLoader loader(optionsIn(dir));
  const LoadEvent first = waitFor(loader, loader.request(tck));
  const LoadEvent second = waitFor(loader, loader.request(tck));
  ASSERT_TRUE(first.ok()) << first.error;
  ASSERT_TRUE(second.ok()) << second.error;
  std::printf("first load %.3f s (compressed, %.3f s), second %.3f s (from cache)\n", first.model->seconds,
              first.model->compress_seconds, second.model->seconds);
  EXPECT_FALSE(first.model->from_cache);
  EXPECT_TRUE(second.model->from_cache);
  EXPECT_EQ(second.model->compress_seconds, 0.0);
  EXPECT_LT(second.model->seconds * 3, first.model->seconds);
  EXPECT_EQ(second.model->points, first.model->points);
  for (int c = 0; c < 3; ++c) {
    EXPECT_EQ(second.model->bounds.min[c], first.model->bounds.min[c]);
    EXPECT_EQ(second.model->bounds.max[c], first.model->bounds.max[c]);
  }
}

TEST(ModelLoader, aMalformedOrTruncatedOrMissingFileIsOneErrorLineAndTheLoaderGoesOn) {
  TempDir dir;
  const std::string good = writePhantomTck(dir, "good.tck", 50);
  const std::string garbage = dir.file("garbage.tck");
  test::writeBytes(garbage, "this is not a tck file\nat all\n");
  const std::string truncated = dir.file("truncated.tck");
  test::writeBytes(truncated, test::readBytes(good).substr(0, 40));  // cut inside the header
  const std::string missing = dir.file("missing.tck");
  const std::string unknown = dir.file("notes.txt");
  test::writeBytes(unknown, "hello");

  ModelLoader loader(optionsIn(dir));
  for (const std::string& bad : {garbage, truncated, missing, unknown}) {
    const LoadEvent event = waitFor(loader, loader.request(bad));
    EXPECT_FALSE(event.ok()) << bad;
    EXPECT_FALSE(event.cancelled);
    EXPECT_NE(event.error.find(bad), std::string::npos) << event.error;
    EXPECT_EQ(event.error.find('\n'), std::string::npos) << event.error;
    // Nothing of the failed job stays in the cache.
    for (const auto& e : std::filesystem::directory_iterator(dir.file("cache")))
      EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();
    const LoadEvent next = waitFor(loader, loader.request(good));
    EXPECT_TRUE(next.ok()) << next.error;
  }
}

TEST(ModelLoader, theEmptyPathIsThePhantomWithTheOptionsCount) {
  TempDir dir;
  ModelLoader loader(optionsIn(dir));
  const LoadEvent event = waitFor(loader, loader.request(""));
  ASSERT_TRUE(event.ok()) << event.error;
  EXPECT_EQ(event.model->streamlines, 200u);
  EXPECT_EQ(event.model->name, "phantom (200 fibers)");
  EXPECT_EQ(event.model->input_bytes, 0u);
  EXPECT_TRUE(waitFor(loader, loader.request("")).model->from_cache);
}

TEST(ModelLoader, aFblInputIsOpenedAsIs) {
  TempDir dir;
  const std::string tck = writePhantomTck(dir, "brain.tck", 50);
  ModelLoader loader(optionsIn(dir));
  const LoadEvent compressed = waitFor(loader, loader.request(tck));
  ASSERT_TRUE(compressed.ok()) << compressed.error;
  const std::string fbl = dir.file("copy.fbl");
  std::filesystem::copy_file(compressed.model->fbl.path(), fbl);
  const LoadEvent event = waitFor(loader, loader.request(fbl));
  ASSERT_TRUE(event.ok()) << event.error;
  EXPECT_TRUE(event.model->from_cache);
  EXPECT_EQ(event.model->points, compressed.model->points);
  EXPECT_EQ(event.model->fbl.path(), fbl);
}

TEST(ModelLoader, progressIsReportedDuringALoad) {
  TempDir dir;
  // Straight through loadModel: every phase's final snapshot arrives.
  std::vector<ProgressSnapshot> seen;
  ModelLoaderOptions options = optionsIn(dir);
  options.phantom_streamlines = 300;
  loadModel("", options, nullptr, [&](const ProgressSnapshot& s) { seen.push_back(s); });
  bool analysing = false, compressing = false;
  for (const ProgressSnapshot& s : seen) {
    // (The phantom has no input size: the analysis counts without a total.)
    analysing = analysing || (s.label == "analysing" && s.done > 0);
    compressing = compressing || (s.label == "compressing" && s.total > 0 && s.done > 0);
  }
  EXPECT_TRUE(analysing);
  EXPECT_TRUE(compressing);

  // Through the loader, polled as the viewer does.
  options.phantom_streamlines = 2000;
  options.cache_dir = dir.file("cache2");
  ModelLoader loader(options);
  const uint64_t id = loader.request("");
  size_t polls_with_progress = 0;
  bool labelled = false;
  while (loader.busy()) {
    for (const LoadProgress& p : loader.progress()) {
      EXPECT_EQ(p.id, id);
      ++polls_with_progress;
      labelled = labelled || p.snapshot.label == "analysing" || p.snapshot.label == "compressing";
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::printf("%zu polls saw progress\n", polls_with_progress);
  EXPECT_GT(polls_with_progress, 0u);
  EXPECT_TRUE(labelled);
  EXPECT_TRUE(loader.poll().at(0).ok());
  EXPECT_TRUE(loader.progress().empty());
}

TEST(ModelLoader, cancellingStopsTheRunningAndQueuedJobsAndLeavesNothing) {
  TempDir dir;
  ModelLoaderOptions options = optionsIn(dir);
  options.phantom_streamlines = 20000;  // long enough to be caught running
  ModelLoader loader(options);
  const uint64_t running = loader.request("");
  const uint64_t queued = loader.request(dir.file("never.tck"));
  while (loader.progress().empty()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  const auto t0 = std::chrono::steady_clock::now();
  loader.cancelAll();
  const LoadEvent a = waitFor(loader, running), b = waitFor(loader, queued);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("cancelled after %.3f s\n", seconds);
  EXPECT_TRUE(a.cancelled) << a.error;
  EXPECT_TRUE(b.cancelled) << b.error;
  EXPECT_FALSE(a.ok());
  EXPECT_LT(seconds, 5.0);
  EXPECT_TRUE(std::filesystem::is_empty(dir.file("cache"))) << "a cancelled load left files behind";
  // Still working afterwards.
  const LoadEvent next = waitFor(loader, loader.request(writePhantomTck(dir, "small.tck", 30)));
  EXPECT_TRUE(next.ok()) << next.error;
}

TEST(ModelLoader, destroyingTheLoaderMidLoadReturnsPromptly) {
  TempDir dir;
  ModelLoaderOptions options = optionsIn(dir);
  options.phantom_streamlines = 20000;
  const auto t0 = std::chrono::steady_clock::now();
  {
    ModelLoader loader(options);
    loader.request("");
    loader.request("");
    while (loader.progress().empty()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5.0);
}

}  // namespace
}  // namespace fibscope
