// `fibscope convert IN OUT`: between all formats, streamed.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "app/open_input.h"
#include "core/output_file.h"
#include "core/progress.h"
#include "io/reader.h"
#include "io/writer.h"

namespace fibscope {

void addConvertCommand(CLI::App& app) {
  struct Options {
    std::string input, output;
    bool force = false;
    WriterOptions writer;
    bool trx_directory = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("convert", "Convert between .tck, .trk, .trx (and read .vtk, .vtp, .tt.gz, .fbl)");
  cmd->add_option("input", opt->input, "Input tractogram")->required();
  cmd->add_option("output", opt->output, "Output tractogram (.tck .trk .trx)")->required();
  cmd->add_flag("--force,-f", opt->force, "Overwrite the output if it exists");
  cmd->add_option("--tck-datatype", opt->writer.tck_datatype, "tck datatype")
      ->check(CLI::IsMember({"Float32LE", "Float32BE", "Float64LE", "Float64BE"}));
  cmd->add_option("--trx-positions", opt->writer.trx_position_dtype, "TRX position type")
      ->check(CLI::IsMember({"float16", "float32", "float64"}));
  cmd->add_flag("--trx-directory", opt->trx_directory, "Write TRX as a directory instead of a zip");
  cmd->callback([opt] {
    // Refuse before reading anything: never overwrite silently.
    checkOverwrite(opt->output, opt->force);
    auto reader = openInput(opt->input);
    WriterOptions wo = opt->writer;
    wo.overwrite = opt->force;
    wo.trx_zip = !opt->trx_directory;
    auto writer = createTractogramWriter(opt->output, reader->header(), wo);
    std::error_code ec;
    const auto in_bytes = std::filesystem::is_regular_file(opt->input, ec) ? std::filesystem::file_size(opt->input, ec) : 0;
    Progress progress("converting", double(in_bytes), "bytes");
    Tractogram chunk;
    uint64_t streamlines = 0, points = 0;
    while (reader->read(chunk)) {
      writer->write(chunk);
      streamlines += chunk.streamlineCount();
      points += chunk.pointCount();
      progress.set(double(reader->bytesRead()));
    }
    writer->finish();
    progress.finish();
    for (const auto& w : reader->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
    for (const auto& w : writer->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
    std::printf("wrote %s: %llu streamlines, %llu points\n", opt->output.c_str(),
                static_cast<unsigned long long>(streamlines), static_cast<unsigned long long>(points));
  });
}

}  // namespace fibscope
