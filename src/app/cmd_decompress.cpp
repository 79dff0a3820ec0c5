// `fibscope decompress IN.fbl OUT`: fiblets back to a .tck, .trk or .trx,
// streamed a chunk at a time, with the original's space, header properties
// and per-streamline arrays (from the .fbl's "source" section).
#include <CLI/CLI.hpp>
#include <cstdio>

#include "app/commands.h"
#include "app/open_input.h"
#include "codec/fbl_reader.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/progress.h"
#include "io/writer.h"

namespace fibscope {

void addDecompressCommand(CLI::App& app) {
  struct Options {
    std::string input, output;
    bool force = false;
    WriterOptions writer;
    bool trx_directory = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("decompress", "Decode a .fbl file back to .tck, .trk or .trx");
  cmd->add_option("input", opt->input, "Input .fbl file")->required();
  cmd->add_option("output", opt->output, "Output tractogram (.tck .trk .trx)")->required();
  cmd->add_flag("--force,-f", opt->force, "Overwrite the output if it exists");
  cmd->add_option("--tck-datatype", opt->writer.tck_datatype, "tck datatype")
      ->check(CLI::IsMember({"Float32LE", "Float32BE", "Float64LE", "Float64BE"}));
  cmd->add_option("--trx-positions", opt->writer.trx_position_dtype, "TRX position type")
      ->check(CLI::IsMember({"float16", "float32", "float64"}));
  cmd->add_flag("--trx-directory", opt->trx_directory, "Write TRX as a directory instead of a zip");
  cmd->callback([opt] {
    if (!isFblPath(opt->input))
      fail(opt->input,
           "decompress reads .fbl files (made by `fibscope compress`); use `fibscope convert` for other formats");
    // Refuse before decoding anything: never overwrite silently.
    checkOverwrite(opt->output, opt->force);
    auto reader = openFbl(opt->input);
    WriterOptions wo = opt->writer;
    wo.overwrite = opt->force;
    wo.trx_zip = !opt->trx_directory;
    // The writer works under a temporary name: an error while decoding
    // destroys it unfinished, which leaves no output behind.
    auto writer = createTractogramWriter(opt->output, reader->header(), wo);
    Progress progress("decompressing", double(reader->header().file_bytes), "bytes");
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
    std::printf("wrote %s: %llu streamlines, %llu points (from %s, originally %s)\n", opt->output.c_str(),
                static_cast<unsigned long long>(streamlines), static_cast<unsigned long long>(points),
                opt->input.c_str(),
                reader->header().format.empty() ? "of unknown format" : reader->header().format.c_str());
  });
}

}  // namespace fibscope
