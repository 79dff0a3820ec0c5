// `fibscope phantom OUT`: writes the brain-like synthetic tractogram,
// streamed (a chunk at a time), to any writable format, or straight to
// fiblets (.fbl) through the streaming compressor, so the paper's 10 M-fiber
// case never needs its 100 GB .tck on disk. The generator is deterministic,
// so the compressor's two passes (analyse, encode) see the same fibers.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
#include "app/open_input.h"
#include "codec/compressor.h"
#include "core/output_file.h"
#include "core/progress.h"
#include "io/reader.h"
#include "io/writer.h"
#include "phantom/phantom.h"

namespace fibscope {

void addPhantomCommand(CLI::App& app) {
  struct Options {
    std::string output;
    PhantomOptions phantom;
    bool force = false;
    std::string bundles;
    std::string tracker = "ifod1";
    std::string mix = "whole-brain";
    WriterOptions writer;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("phantom", "Write a synthetic brain-like tractogram (deterministic for a seed)");
  cmd->add_option("output", opt->output, "Output file (.tck .trk .trx .vtk, or .fbl: compressed on the way)")
      ->required();
  cmd->add_option("--streamlines,-n", opt->phantom.streamlines, "Number of streamlines")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40));
  cmd->add_option("--step", opt->phantom.step_mm, "Step length in mm")->capture_default_str();
  cmd->add_option("--max-angle", opt->phantom.max_angle_deg, "Maximum turning angle between segments, degrees")
      ->capture_default_str();
  CLI::Option* jitter =
      cmd->add_option("--jitter", opt->phantom.jitter, "Tracker noise: 1 probabilistic-like, 0 smooth (default: as --tracker)");
  cmd->add_option("--tracker", opt->tracker,
                  "Curvature like MRtrix3 iFOD1 output (probabilistic: jitter 1) or SD_STREAM output "
                  "(deterministic: jitter 0.1, turns well under a degree per 0.1 mm step)")
      ->capture_default_str()
      ->check(CLI::IsMember({"ifod1", "sd_stream"}));
  cmd->add_option("--bundles", opt->bundles,
                  "Bundle mix, e.g. corpus_callosum=2,u_fibers=0 (others keep their default weight)");
  cmd->add_option("--mix", opt->mix,
                  "whole-brain: fibers throughout the white matter (the wm_* families, 87 % of them) beside the "
                  "named bundles 2.5 times as thick, so it fills and occludes like whole-brain tracking; bundles: "
                  "the named bundles alone, thin and well apart; --bundles then changes the mix")
      ->capture_default_str()
      ->check(CLI::IsMember({"whole-brain", "bundles"}));
  cmd->add_option("--seed", opt->phantom.seed, "Random seed")->capture_default_str();
  cmd->add_option("--min-length", opt->phantom.min_length_mm, "Minimum fiber length in mm")->capture_default_str();
  cmd->add_option("--max-length", opt->phantom.max_length_mm, "Maximum fiber length in mm")->capture_default_str();
  cmd->add_option("--threads", opt->phantom.threads, "Generator threads (0: all cores)")->capture_default_str();
  cmd->add_option("--tck-datatype", opt->writer.tck_datatype, "tck datatype")
      ->check(CLI::IsMember({"Float32LE", "Float32BE", "Float64LE", "Float64BE"}));
  cmd->add_option("--trx-positions", opt->writer.trx_position_dtype, "TRX position type")
      ->check(CLI::IsMember({"float16", "float32", "float64"}));
  cmd->add_flag("--force,-f", opt->force, "Overwrite the output if it exists");
  cmd->callback([opt, jitter] {
    if (jitter->count() == 0) opt->phantom.jitter = opt->tracker == "sd_stream" ? 0.1 : 1.0;
    checkOverwrite(opt->output, opt->force);
    if (opt->mix == "bundles") applyNamedBundlesPhantomMix(opt->phantom);
    // --bundles changes the chosen mix.
    if (!opt->bundles.empty())
      opt->phantom.bundle_weights = parsePhantomBundleMix(opt->bundles, opt->phantom.bundle_weights);
    if (isFblPath(opt->output)) {
      CompressOptions options;
      options.overwrite = opt->force;
      const PhantomOptions phantom = opt->phantom;
      const CompressReport r = compressTractogram([phantom] { return openPhantom(phantom); }, opt->output, options);
      for (const auto& w : r.warnings) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
      std::printf("wrote %s: %llu streamlines, %llu points, %llu fiblets, %s; error max %.2f um, mean %.2f um; "
                  "%.1f s, %s points/s\n",
                  opt->output.c_str(), static_cast<unsigned long long>(r.fibers),
                  static_cast<unsigned long long>(r.points), static_cast<unsigned long long>(r.fiblets),
                  formatBytes(double(r.output_bytes)).c_str(), r.error.max_um, r.error.mean_um, r.seconds(),
                  formatCount(r.pointsPerSecond()).c_str());
      return;
    }
    auto reader = openPhantom(opt->phantom);
    WriterOptions wo = opt->writer;
    wo.overwrite = opt->force;
    auto writer = createTractogramWriter(opt->output, reader->header(), wo);
    Progress progress("phantom", double(opt->phantom.streamlines), "streamlines");
    Tractogram chunk;
    uint64_t points = 0;
    while (reader->read(chunk)) {
      writer->write(chunk);
      points += chunk.pointCount();
      progress.add(double(chunk.streamlineCount()));
    }
    writer->finish();
    progress.finish();
    for (const auto& w : writer->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
    std::printf("wrote %s: %llu streamlines, %llu points\n", opt->output.c_str(),
                static_cast<unsigned long long>(opt->phantom.streamlines), static_cast<unsigned long long>(points));
  });
}

}  // namespace fibscope
