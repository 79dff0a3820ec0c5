// `fibscope info FILE...`: counts, geometry statistics and data arrays; for
// a .fbl also the container and codec facts, every section's checksum and
// what the original file was.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>

#include "app/commands.h"
#include "app/open_input.h"
#include "codec/fbl_file.h"
#include "core/error.h"
#include "core/progress.h"
#include "io/fiber_density.h"
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

// What a .fbl holds besides the streamlines. Gathered from the container
// alone, so that a file whose fiblets fail to decode can still show which
// section is damaged.
struct FblSectionInfo {
  FblSection section;
  bool checksum_ok = false;
};

struct FblInfo {
  uint32_t format_version = 0;
  FblHeaderFields fields;
  uint64_t file_bytes = 0;
  std::vector<FblSectionInfo> sections;
  // From the "source" JSON, when it is intact and parses.
  std::string source_format, source_path;
  std::vector<DataArray> dropped_per_point;
};

FblInfo inspectFbl(const std::string& path) {
  const FblFile file = FblFile::open(path);
  FblInfo info;
  info.format_version = file.formatVersion();
  info.fields = file.header();
  info.file_bytes = file.fileBytes();
  for (const FblSection& s : file.sections()) {
    FblSectionInfo si{s, true};
    try {
      file.verify(s.name);
    } catch (const Error&) {
      si.checksum_ok = false;
    }
    info.sections.push_back(std::move(si));
    if (s.name == kFblSectionSource && info.sections.back().checksum_ok && s.dtype == FblDType::kUtf8) {
      // Best effort: the reader reports a malformed source section itself.
      const auto text = file.data(s);
      const auto j = nlohmann::json::parse(text.begin(), text.end(), nullptr, /*allow_exceptions=*/false);
      if (j.is_object()) try {
        if (j.contains("format") && j["format"].is_string()) info.source_format = j["format"];
        if (j.contains("path") && j["path"].is_string()) info.source_path = j["path"];
        if (j.contains("dropped_per_point") && j["dropped_per_point"].is_array())
          for (const auto& a : j["dropped_per_point"])
            if (a.is_object() && a.contains("name") && a["name"].is_string())
              info.dropped_per_point.push_back(
                  {a["name"], a.value("components", 1u), a.value("dtype", std::string("float32")), {}});
      } catch (const nlohmann::json::exception&) {
        // A field of the wrong type: left out here, reported by the reader.
      }
    }
  }
  return info;
}

double bytesPerPoint(const FblInfo& f) {
  return f.fields.point_count ? double(f.file_bytes) / double(f.fields.point_count) : 0.0;
}

double alphaDegrees(const FblInfo& f) { return f.fields.alpha * 180.0 / std::numbers::pi; }

nlohmann::json fblJson(const FblInfo& f) {
  nlohmann::json j;
  j["format_version"] = f.format_version;
  j["codec_version"] = f.fields.codec_version;
  j["points_per_fiblet"] = f.fields.points_per_fiblet;
  j["record_bytes"] = f.fields.fiblet_record_bytes;
  j["delta_mm"] = f.fields.delta_mm;
  j["alpha_deg"] = alphaDegrees(f);
  j["v"] = {f.fields.v[0], f.fields.v[1], f.fields.v[2]};
  j["translation_mm"] = {f.fields.translation[0], f.fields.translation[1], f.fields.translation[2]};
  j["scale_mm"] = f.fields.scale;
  j["fibers"] = f.fields.fiber_count;
  j["fiblets"] = f.fields.fiblet_count;
  j["points"] = f.fields.point_count;
  j["file_bytes"] = f.file_bytes;
  j["bytes_per_point"] = bytesPerPoint(f);
  nlohmann::json sections = nlohmann::json::array();
  for (const auto& si : f.sections)
    sections.push_back({{"name", si.section.name},
                        {"dtype", fblDTypeName(si.section.dtype)},
                        {"components", si.section.components},
                        {"elements", si.section.element_count},
                        {"offset", si.section.offset},
                        {"bytes", si.section.bytes},
                        {"checksum_ok", si.checksum_ok}});
  j["sections"] = sections;
  j["source"] = {{"format", f.source_format}, {"path", f.source_path}, {"dropped_per_point", arraysJson(f.dropped_per_point)}};
  return j;
}

void printFbl(const FblInfo& f) {
  const FblHeaderFields& h = f.fields;
  std::printf("  fbl container         version %u, fiblet codec version %u\n", f.format_version, h.codec_version);
  std::printf("  fiblets               N = %u points, %u-byte records\n", h.points_per_fiblet, h.fiblet_record_bytes);
  std::printf("  codec                 delta %.6g mm, alpha %.4g deg, V [%.6g %.6g %.6g]\n", h.delta_mm,
              alphaDegrees(f), double(h.v[0]), double(h.v[1]), double(h.v[2]));
  std::printf("  encoded               %llu fibers, %llu fiblets, %llu points\n",
              static_cast<unsigned long long>(h.fiber_count), static_cast<unsigned long long>(h.fiblet_count),
              static_cast<unsigned long long>(h.point_count));
  std::printf("  size                  %llu bytes, %.4g bytes per point\n", static_cast<unsigned long long>(f.file_bytes),
              bytesPerPoint(f));
  std::printf("  sections\n");
  for (const auto& si : f.sections) {
    const FblSection& s = si.section;
    const std::string type = fblDTypeName(s.dtype) + " x " + std::to_string(s.components);
    std::printf("    %-22s %-14s %12llu elements %14llu bytes  CRC %s\n", s.name.c_str(), type.c_str(),
                static_cast<unsigned long long>(s.element_count), static_cast<unsigned long long>(s.bytes),
                si.checksum_ok ? "ok" : "BAD");
  }
  std::printf("  original              %s %s\n", f.source_format.empty() ? "(unknown)" : f.source_format.c_str(),
              f.source_path.c_str());
  std::printf("  dropped per-point     %s\n", arrayList(f.dropped_per_point).c_str());
}

struct InfoResult {
  TractogramHeader header;
  TractogramStats stats;
  std::optional<FiberDensity> density;
  uint64_t bytes = 0;
  std::vector<std::string> warnings;
};

// density_voxel_mm 0: no density statistic.
InfoResult inspect(const std::string& path, bool terminal_progress, double density_voxel_mm) {
  InfoResult r;
  r.bytes = pathBytes(path);
  auto reader = openInput(path);
  Progress progress("reading " + std::filesystem::path(path).filename().string(), double(r.bytes), "bytes",
                    terminal_progress);
  TractogramStatsAccumulator acc;
  std::optional<FiberDensityAccumulator> density;
  if (density_voxel_mm > 0) density.emplace(density_voxel_mm);
  Tractogram chunk;
  while (reader->read(chunk)) {
    acc.add(chunk);
    if (density) density->add(chunk);
    progress.set(double(reader->bytesRead()));
  }
  progress.finish();
  r.header = reader->header();
  r.stats = acc.result();
  if (density) r.density = density->result();
  r.warnings = reader->warnings();
  return r;
}

nlohmann::json toJson(const std::string& path, const InfoResult& r, const std::optional<FblInfo>& fbl) {
  const TractogramStats& s = r.stats;
  nlohmann::json j;
  j["path"] = path;
  j["format"] = fbl ? std::string("fbl") : r.header.format;
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
  if (r.density) {
    const FiberDensity& d = *r.density;
    j["fiber_density"] = {{"voxel_mm", d.voxel_mm},
                          {"occupied_voxels", d.occupied_voxels},
                          {"occupied_cm3", d.occupied_cm3},
                          {"fibers_per_voxel",
                           {{"mean", d.mean}, {"median", d.median}, {"p90", d.p90}, {"p99", d.p99}, {"max", d.max}}},
                          {"single_fiber_fraction", d.single_fiber_fraction},
                          {"histogram_log2", d.histogram}};
  }
  j["warnings"] = r.warnings;
  if (fbl) j["fbl"] = fblJson(*fbl);
  return j;
}

void printText(const std::string& path, const InfoResult& r, const std::optional<FblInfo>& fbl) {
  const TractogramStats& s = r.stats;
  std::printf("%s\n", path.c_str());
  if (fbl) {
    std::printf("  format                fbl (fiblets; original %s)\n", r.header.format.c_str());
    printFbl(*fbl);
  } else {
    std::printf("  format                %s\n", r.header.format.c_str());
  }
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
  if (r.density) {
    const FiberDensity& d = *r.density;
    std::printf("  fiber density         %llu voxels of %.3g mm occupied (%.4g cm3); fibers per voxel mean %.3g  "
                "median %llu  p90 %llu  p99 %llu  max %llu  (%.1f %% of voxels one fiber)\n",
                static_cast<unsigned long long>(d.occupied_voxels), d.voxel_mm, d.occupied_cm3, d.mean,
                static_cast<unsigned long long>(d.median), static_cast<unsigned long long>(d.p90),
                static_cast<unsigned long long>(d.p99), static_cast<unsigned long long>(d.max),
                100.0 * d.single_fiber_fraction);
  }
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
    double density_voxel_mm = 1.0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("info", "Counts, step, turning angle, extent and data of tractogram files");
  cmd->add_option("files", opt->files, "Tractogram files (.tck .trk .trk.gz .tt.gz .trx .vtk .vtp .fbl)")->required();
  cmd->add_flag("--json", opt->json, "Print one JSON document for all files");
  cmd->add_option("--density-voxel", opt->density_voxel_mm,
                  "Voxel size in mm of the fiber density statistic (distinct fibers per occupied voxel); 0: off")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 100.0));
  cmd->callback([opt] {
    nlohmann::json all = nlohmann::json::array();
    for (const auto& path : opt->files) {
      std::optional<FblInfo> fbl;
      if (isFblPath(path)) fbl = inspectFbl(path);
      InfoResult r;
      try {
        r = inspect(path, !opt->json, opt->density_voxel_mm);
      } catch (const Error&) {
        // Show the container (which section is damaged) before the error.
        if (fbl && !opt->json) {
          std::printf("%s\n", path.c_str());
          printFbl(*fbl);
          std::fflush(stdout);
        }
        throw;
      }
      for (const auto& w : r.warnings) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
      if (opt->json)
        all.push_back(toJson(path, r, fbl));
      else
        printText(path, r, fbl);
    }
    if (opt->json) std::printf("%s\n", all.dump(2).c_str());
  });
}

}  // namespace fibscope
