// `fibscope info FILE...`: counts, geometry statistics and data arrays.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "app/commands.h"
#include "core/progress.h"
#include "io/reader.h"
#include "io/tractogram_stats.h"

namespace fibscope {
namespace {

uint64_t pathBytes(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    uint64_t total = 0;
    for (const auto& e : fs::recursive_directory_iterator(path, ec))
      if (e.is_regular_file(ec)) total += e.file_size(ec);
    return total;
  }
  const auto size = fs::file_size(path, ec);
  return ec ? 0 : size;
}

std::string arrayList(const std::vector<DataArray>& arrays) {
  if (arrays.empty()) return "none";
  std::string s;
  for (const auto& a : arrays) {
    if (!s.empty()) s += ", ";
    s += a.name + (a.components > 1 ? " (" + std::to_string(a.components) + " x " + a.dtype + ")" : " (" + a.dtype + ")");
  }
  return s;
}

nlohmann::json arraysJson(const std::vector<DataArray>& arrays) {
  nlohmann::json j = nlohmann::json::array();
  for (const auto& a : arrays) j.push_back({{"name", a.name}, {"components", a.components}, {"dtype", a.dtype}});
  return j;
}

struct InfoResult {
  TractogramHeader header;
  TractogramStats stats;
  uint64_t bytes = 0;
  std::vector<std::string> warnings;
};

InfoResult inspect(const std::string& path, bool terminal_progress) {
  InfoResult r;
  r.bytes = pathBytes(path);
  auto reader = openTractogram(path);
  Progress progress("reading " + std::filesystem::path(path).filename().string(), double(r.bytes), "bytes",
                    terminal_progress);
  TractogramStatsAccumulator acc;
  Tractogram chunk;
  while (reader->read(chunk)) {
    acc.add(chunk);
    progress.set(double(reader->bytesRead()));
  }
  progress.finish();
  r.header = reader->header();
  r.stats = acc.result();
  r.warnings = reader->warnings();
  return r;
}

nlohmann::json toJson(const std::string& path, const InfoResult& r) {
  const TractogramStats& s = r.stats;
  nlohmann::json j;
  j["path"] = path;
  j["format"] = r.header.format;
  j["file_bytes"] = r.bytes;
  j["streamlines"] = s.streamlines;
  j["points"] = s.points;
  j["segments"] = s.segments;
  j["declared_streamlines"] = r.header.declared_streamlines;
  j["empty_streamlines"] = s.empty_streamlines;
  j["single_point_streamlines"] = s.single_point_streamlines;
  j["zero_length_segments"] = s.zero_length_segments;
  j["step_mm"] = {{"min", s.step_min}, {"median", s.step_median}, {"max", s.step_max},
                  {"fraction_within_1pct_of_median", s.step_within_1pct}};
  j["turning_angle_deg"] = {{"mean", s.angle_mean_deg}, {"p50", s.angle_p50_deg}, {"p99", s.angle_p99_deg},
                            {"p99_9", s.angle_p999_deg}, {"max", s.angle_max_deg}};
  j["bounding_box_mm"] = {{"min", s.bbox_min}, {"max", s.bbox_max}};
  j["length_mm"] = {{"min", s.length_min}, {"mean", s.length_mean}, {"max", s.length_max}};
  j["per_streamline"] = arraysJson(r.header.per_streamline);
  j["per_point"] = arraysJson(r.header.per_point);
  nlohmann::json groups = nlohmann::json::array();
  for (const auto& g : r.header.groups) groups.push_back({{"name", g.name}, {"streamlines", g.streamlines.size()}});
  j["groups"] = groups;
  if (r.header.space.known) {
    j["voxel_to_rasmm"] = r.header.space.voxel_to_rasmm;
    j["dimensions"] = r.header.space.dimensions;
    j["voxel_sizes"] = r.header.space.voxel_sizes;
  }
  j["warnings"] = r.warnings;
  return j;
}

void printText(const std::string& path, const InfoResult& r) {
  const TractogramStats& s = r.stats;
  std::printf("%s\n", path.c_str());
  std::printf("  format                %s\n", r.header.format.c_str());
  std::printf("  file size             %s (%llu bytes)\n", formatBytes(double(r.bytes)).c_str(),
              static_cast<unsigned long long>(r.bytes));
  std::printf("  streamlines           %llu", static_cast<unsigned long long>(s.streamlines));
  if (s.empty_streamlines || s.single_point_streamlines)
    std::printf("  (%llu empty, %llu single-point)", static_cast<unsigned long long>(s.empty_streamlines),
                static_cast<unsigned long long>(s.single_point_streamlines));
  std::printf("\n");
  std::printf("  points                %llu\n", static_cast<unsigned long long>(s.points));
  std::printf("  segments              %llu\n", static_cast<unsigned long long>(s.segments));
  std::printf("  step (mm)             min %.6g  median %.6g  max %.6g  (%.2f %% within 1 %% of median)\n",
              s.step_min, s.step_median, s.step_max, 100.0 * s.step_within_1pct);
  if (s.zero_length_segments)
    std::printf("  zero-length segments  %llu\n", static_cast<unsigned long long>(s.zero_length_segments));
  std::printf("  turning angle (deg)   mean %.3f  median %.3f  p99 %.3f  p99.9 %.3f  max %.3f\n", s.angle_mean_deg,
              s.angle_p50_deg, s.angle_p99_deg, s.angle_p999_deg, s.angle_max_deg);
  std::printf("  bounding box (mm)     [%.2f %.2f %.2f] .. [%.2f %.2f %.2f]\n", s.bbox_min[0], s.bbox_min[1],
              s.bbox_min[2], s.bbox_max[0], s.bbox_max[1], s.bbox_max[2]);
  std::printf("  length (mm)           min %.3f  mean %.3f  max %.3f\n", s.length_min, s.length_mean, s.length_max);
  std::printf("  per-streamline data   %s\n", arrayList(r.header.per_streamline).c_str());
  std::printf("  per-point data        %s\n", arrayList(r.header.per_point).c_str());
  if (!r.header.groups.empty()) {
    std::printf("  groups               ");
    for (const auto& g : r.header.groups) std::printf(" %s (%zu)", g.name.c_str(), g.streamlines.size());
    std::printf("\n");
  }
}

}  // namespace

void addInfoCommand(CLI::App& app) {
  struct Options {
    std::vector<std::string> files;
    bool json = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("info", "Counts, step, turning angle, extent and data of tractogram files");
  cmd->add_option("files", opt->files, "Tractogram files (.tck .trk .trx .vtk)")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON document for all files");
  cmd->callback([opt] {
    nlohmann::json all = nlohmann::json::array();
    for (const auto& path : opt->files) {
      const InfoResult r = inspect(path, !opt->json);
      for (const auto& w : r.warnings) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
      if (opt->json)
        all.push_back(toJson(path, r));
      else
        printText(path, r);
    }
    if (opt->json) std::printf("%s\n", all.dump(2).c_str());
  });
}

}  // namespace fibscope
