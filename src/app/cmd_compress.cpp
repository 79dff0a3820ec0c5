// `fibscope compress IN OUT.fbl`: the fiblet encoder over any input, with
// the report the issue asks for (sizes, error, exceptions, speed).
#include <CLI/CLI.hpp>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>

#include "app/commands.h"
#include "app/open_input.h"
#include "codec/compressor.h"
#include "core/error.h"
#include "core/progress.h"

namespace fibscope {

namespace {

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

std::string modeName(const CompressReport& r, int side) {
  switch (r.mode) {
    case EncodeMode::ClosedLoop:
      return "closed loop (" + std::to_string(side) + "x" + std::to_string(side) + " cell search)";
    case EncodeMode::OpenLoop:
      return "open loop (the paper's)";
    case EncodeMode::TrueFrame:
      return "true-frame open loop";
  }
  return "?";
}

void printReport(const CompressReport& r, int side, bool full) {
  const CodecParams& p = r.analysis.params;
  std::printf(
      "wrote %s: %llu fibers, %llu points, %llu fiblets, %s (%.3f bytes/point); error max %.2f um, mean %.2f um\n",
      r.output.c_str(), static_cast<unsigned long long>(r.fibers), static_cast<unsigned long long>(r.points),
      static_cast<unsigned long long>(r.fiblets), formatBytes(double(r.output_bytes)).c_str(), r.bytesPerPoint(),
      r.error.max_um, r.error.mean_um);
  if (!full) return;
  std::printf("  input       %s (%s, %s)\n", r.input.c_str(), r.input_format.c_str(),
              formatBytes(double(r.input_bytes)).c_str());
  std::printf("  size        %llu bytes in all: fiblets %llu, tables and header %llu; %.3f bytes/point; ratio %.2fx\n",
              static_cast<unsigned long long>(r.output_bytes), static_cast<unsigned long long>(r.fiblet_bytes),
              static_cast<unsigned long long>(r.output_bytes - r.fiblet_bytes), r.bytesPerPoint(), r.ratio());
  std::printf("  step        %.6g mm (%s)\n", p.deltaMm(),
              r.analysis.delta_measured
                  ? ("median of " + std::to_string(r.analysis.sampled_steps) + " sampled steps").c_str()
                  : "given");
  if (r.analysis.alpha_measured)
    std::printf(
        "  alpha       %.3f deg = 1.1 x the 99.9th percentile turn (%.3f deg, of %llu sampled turns), clamped to "
        "[1, 90]; largest turn %.2f deg\n",
        degrees(p.alpha), r.analysis.turn_percentile_deg, static_cast<unsigned long long>(r.analysis.sampled_turns),
        r.analysis.max_turn_deg);
  else
    std::printf("  alpha       %.3f deg (given); largest turn %.2f deg\n", degrees(p.alpha), r.analysis.max_turn_deg);
  std::printf("  fiblets     N = %u points (%u-byte records), %s, %u threads\n", p.points_per_fiblet, p.recordBytes(),
              modeName(r, side).c_str(), r.threads);
  std::printf("  error       max %.3f um, mean %.3f um, p99 %.2f um, rms %.3f um over %llu points (world space)\n",
              r.error.max_um, r.error.mean_um, r.error.p99_um, r.error.rms_um,
              static_cast<unsigned long long>(r.error.points));
  const EncodeReport& e = r.encode;
  std::printf(
      "  exceptions  %llu turns above alpha, %llu steps off the step by > 5%%, %llu closed-loop error splits "
      "(each starts a fiblet); %llu one-point and %llu two-point fibers; %llu points clamped into the box\n",
      static_cast<unsigned long long>(e.angle_splits), static_cast<unsigned long long>(e.step_splits),
      static_cast<unsigned long long>(e.error_splits), static_cast<unsigned long long>(e.single_point_fibers),
      static_cast<unsigned long long>(e.two_point_fibers), static_cast<unsigned long long>(e.clamped_points));
  if (r.resampled)
    std::printf(
        "  resampled   %llu -> %llu points (%llu moved); input points lie within max %.3f um, mean %.3f um of "
        "the resampled fibers (the error above is against the resampled points)\n",
        static_cast<unsigned long long>(r.resample.input_points),
        static_cast<unsigned long long>(r.resample.output_points),
        static_cast<unsigned long long>(r.resample.moved_points), 1000 * r.resample.max_deviation_mm,
        1000 * r.resample.mean_deviation_mm);
  for (const std::string& d : r.dropped) std::printf("  not stored  %s\n", d.c_str());
  std::printf("  time        %.2f s (analyse %.2f s, encode and write %.2f s): %s points/s\n", r.seconds(),
              r.analyse_seconds, r.encode_seconds, formatCount(r.pointsPerSecond()).c_str());
}

nlohmann::json reportJson(const CompressReport& r, int side) {
  const CodecParams& p = r.analysis.params;
  const EncodeReport& e = r.encode;
  nlohmann::json j;
  j["input"] = {{"path", r.input}, {"format", r.input_format}, {"bytes", r.input_bytes}};
  j["output"] = {{"path", r.output}, {"bytes", r.output_bytes}, {"fiblet_bytes", r.fiblet_bytes}};
  j["fibers"] = r.fibers;
  j["points"] = r.points;
  j["fiblets"] = r.fiblets;
  j["bytes_per_point"] = r.bytesPerPoint();
  j["ratio"] = r.ratio();
  j["params"] = {{"points_per_fiblet", p.points_per_fiblet},    {"step_mm", p.deltaMm()},
                 {"step_measured", r.analysis.delta_measured},  {"alpha_deg", degrees(p.alpha)},
                 {"alpha_measured", r.analysis.alpha_measured}, {"turn_p99_9_deg", r.analysis.turn_percentile_deg},
                 {"max_turn_deg", r.analysis.max_turn_deg},     {"steps_off_fraction", r.analysis.steps_off_fraction}};
  j["mode"] = modeName(r, side);
  j["threads"] = r.threads;
  j["error_um"] = {{"max", r.error.max_um},
                   {"mean", r.error.mean_um},
                   {"p99", r.error.p99_um},
                   {"rms", r.error.rms_um},
                   {"points", r.error.points}};
  j["exceptions"] = {{"angle_splits", e.angle_splits},         {"step_splits", e.step_splits},
                     {"error_splits", e.error_splits},         {"single_point_fibers", e.single_point_fibers},
                     {"two_point_fibers", e.two_point_fibers}, {"clamped_points", e.clamped_points}};
  if (r.resampled)
    j["resampled"] = {{"input_points", r.resample.input_points},
                      {"output_points", r.resample.output_points},
                      {"moved_points", r.resample.moved_points},
                      {"max_deviation_um", 1000 * r.resample.max_deviation_mm},
                      {"mean_deviation_um", 1000 * r.resample.mean_deviation_mm}};
  j["not_stored"] = r.dropped;
  j["warnings"] = r.warnings;
  j["seconds"] = {{"analyse", r.analyse_seconds}, {"encode", r.encode_seconds}, {"total", r.seconds()}};
  j["points_per_second"] = r.pointsPerSecond();
  return j;
}

}  // namespace

void addCompressCommand(CLI::App& app) {
  struct Options {
    std::string input, output;
    bool open_loop = false, report = false, json = false, force = false;
    CompressOptions compress;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("compress", "Compress a tractogram into fiblets (.fbl)");
  cmd->add_option("input", opt->input, "Input tractogram (.tck .trk .trk.gz .tt.gz .trx .vtk .vtp .fbl)")->required();
  cmd->add_option("output", opt->output, "Output .fbl file")->required();
  cmd->add_flag("--open-loop", opt->open_loop,
                "Encode as the fiblets paper does (each direction quantised on its own) instead of closed loop");
  cmd->add_option("--points", opt->compress.params.points_per_fiblet, "Points per fiblet N (multiple of 4, 8..60)")
      ->capture_default_str()
      ->check(CLI::Range(8u, 60u));
  cmd->add_option("--step", opt->compress.params.delta_mm, "Step in mm (default: the median segment length)");
  cmd->add_option("--max-angle", opt->compress.params.alpha_deg,
                  "Maximum turn alpha in degrees (default: 1.1 x the 99.9th percentile turn)");
  cmd->add_flag("--resample", opt->compress.resample,
                "Resample fibers to the step along their arc length first (for files whose steps vary)");
  cmd->add_option("--threads", opt->compress.threads, "Encoding threads (0: all cores)")->capture_default_str();
  cmd->add_flag("--report", opt->report, "Print the full report: sizes, parameters, error, exceptions, time");
  cmd->add_flag("--json", opt->json, "Print the report as JSON");
  cmd->add_flag("--force,-f", opt->force, "Overwrite the output if it exists");
  cmd->callback([opt] {
    if (opt->compress.params.points_per_fiblet % 4 != 0)
      throw CLI::ValidationError("--points", "must be a multiple of 4");
    // Other tools would take an .fbl under another extension for that format.
    if (!isFblPath(opt->output)) fail(opt->output, "the output of compress must be a .fbl file");
    CompressOptions options = opt->compress;
    options.overwrite = opt->force;
    if (opt->open_loop) options.encode.mode = EncodeMode::OpenLoop;
    const std::string input = opt->input;
    const CompressReport r = compressTractogram([&input] { return openInput(input); }, opt->output, options);
    for (const auto& w : r.warnings) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
    if (opt->json)
      std::printf("%s\n", reportJson(r, options.encode.search_size).dump(2).c_str());
    else
      printReport(r, options.encode.search_size, opt->report);
  });
}

}  // namespace fibscope
