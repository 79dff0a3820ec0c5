// `fibscope phantom OUT`: writes the brain-like synthetic tractogram,
// streamed (a chunk at a time), to any writable format.
#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
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
    WriterOptions writer;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("phantom", "Write a synthetic brain-like tractogram (deterministic for a seed)");
  cmd->add_option("output", opt->output, "Output file (.tck .trk .trx)")->required();
  cmd->add_option("--streamlines,-n", opt->phantom.streamlines, "Number of streamlines")
      ->capture_default_str()
      ->check(CLI::Range(uint64_t(1), uint64_t(1) << 40));
  cmd->add_option("--step", opt->phantom.step_mm, "Step length in mm")->capture_default_str();
  cmd->add_option("--max-angle", opt->phantom.max_angle_deg, "Maximum turning angle between segments, degrees")
      ->capture_default_str();
  cmd->add_option("--jitter", opt->phantom.jitter, "Tracker noise: 1 probabilistic-like, 0 smooth")->capture_default_str();
  cmd->add_option("--bundles", opt->bundles,
                  "Bundle mix, e.g. corpus_callosum=2,u_fibers=0 (others keep their default weight)");
  cmd->add_option("--seed", opt->phantom.seed, "Random seed")->capture_default_str();
  cmd->add_option("--min-length", opt->phantom.min_length_mm, "Minimum fiber length in mm")->capture_default_str();
  cmd->add_option("--max-length", opt->phantom.max_length_mm, "Maximum fiber length in mm")->capture_default_str();
  cmd->add_option("--threads", opt->phantom.threads, "Generator threads (0: all cores)")->capture_default_str();
  cmd->add_option("--tck-datatype", opt->writer.tck_datatype, "tck datatype")
      ->check(CLI::IsMember({"Float32LE", "Float32BE", "Float64LE", "Float64BE"}));
  cmd->add_option("--trx-positions", opt->writer.trx_position_dtype, "TRX position type")
      ->check(CLI::IsMember({"float16", "float32", "float64"}));
  cmd->add_flag("--force,-f", opt->force, "Overwrite the output if it exists");
  cmd->callback([opt] {
    checkOverwrite(opt->output, opt->force);
    if (!opt->bundles.empty()) opt->phantom.bundle_weights = parsePhantomBundleMix(opt->bundles);
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
