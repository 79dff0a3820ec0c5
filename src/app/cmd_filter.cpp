// `fibscope filter IN OUT`: the streamlines that criteria keep (regions of
// interest, lengths), as MRtrix3's tckedit keeps them, from any format to
// any format, streamed, on every core, with how many each criterion dropped.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "app/open_input.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/progress.h"
#include "io/writer.h"
#include "select/filter_run.h"

namespace fibscope {
namespace {

struct FilterOptions {
  std::string input, output;
  std::vector<std::string> include, include_ordered, exclude;
  bool ends_only = false;
  double min_length = NAN, max_length = NAN;
  bool force = false;
  unsigned threads = 0;
};

std::vector<Region> regions(const std::vector<std::string>& specs, const char* option) {
  std::vector<Region> out;
  for (const std::string& spec : specs) {
    try {
      out.push_back(parseRegion(spec));
    } catch (const Error& e) {
      throw Error(std::string(option) + " " + e.what());
    }
  }
  return out;
}

std::string percent(uint64_t part, uint64_t whole) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %%", whole ? 100.0 * double(part) / double(whole) : 0.0);
  return buf;
}

void runFilterCommand(const FilterOptions& o) {
  FilterCriteria criteria;
  criteria.include = regions(o.include, "--include");
  criteria.include_ordered = regions(o.include_ordered, "--include-ordered");
  criteria.exclude = regions(o.exclude, "--exclude");
  criteria.ends_only = o.ends_only;
  for (const auto& [value, name] : {std::pair{o.min_length, "--min-length"}, std::pair{o.max_length, "--max-length"}})
    if (!std::isnan(value) && !(value >= 0 && std::isfinite(value)))
      throw Error(std::string(name) + ": expected a length >= 0 mm");
  criteria.min_length_mm = o.min_length;
  criteria.max_length_mm = o.max_length;
  // Refuse before reading anything: never overwrite silently.
  checkOverwrite(o.output, o.force);
  const auto start = std::chrono::steady_clock::now();
  auto reader = openInput(o.input);
  const FiberFilter filter(criteria, headerStepSize(reader->header()));
  WriterOptions wo;
  wo.overwrite = o.force;
  auto writer = createTractogramWriter(o.output, reader->header(), wo);
  std::error_code ec;
  const auto bytes = std::filesystem::is_regular_file(o.input, ec) ? std::filesystem::file_size(o.input, ec) : 0;
  Progress progress("filtering", double(bytes), "bytes");
  const FilterReport r = runFilter(*reader, *writer, filter, o.threads,
                                   [&](uint64_t done) { progress.set(double(done)); });
  writer->finish();
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const auto& w : reader->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
  for (const auto& w : writer->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
  std::printf("wrote %s: %llu of %llu streamlines kept (%s), %llu points, %.2f s\n", o.output.c_str(),
              static_cast<unsigned long long>(r.kept), static_cast<unsigned long long>(r.streamlines),
              percent(r.kept, r.streamlines).c_str(), static_cast<unsigned long long>(r.kept_points), seconds);
  auto dropped = [&](const std::string& what, uint64_t n) {
    std::printf("  dropped %llu (%s): %s\n", static_cast<unsigned long long>(n), percent(n, r.streamlines).c_str(),
                what.c_str());
  };
  if (!std::isnan(o.min_length) || !std::isnan(o.max_length) || r.by_length > 0) dropped("length", r.by_length);
  for (size_t i = 0; i < r.by_exclude.size(); ++i) dropped("entered --exclude " + o.exclude[i], r.by_exclude[i]);
  for (size_t i = 0; i < r.by_include.size(); ++i) dropped("missed --include " + o.include[i], r.by_include[i]);
  if (!o.include_ordered.empty()) dropped("missed the --include-ordered regions or their order", r.by_order);
}

}  // namespace

void addFilterCommand(CLI::App& app) {
  auto o = std::make_shared<FilterOptions>();
  CLI::App* cmd = app.add_subcommand(
      "filter", "Keep the streamlines that pass regions of interest and length limits (as MRtrix3's tckedit)");
  cmd->add_option("input", o->input, "Input tractogram (.tck .trk .trx .vtk .fbl)")->required();
  cmd->add_option("output", o->output, "Output tractogram (.tck .trk .trx)")->required();
  cmd->add_option("--include", o->include,
                  "A region every kept streamline has a vertex in: sphere:X,Y,Z,R (or X,Y,Z,R), "
                  "box:X0,Y0,Z0,X1,Y1,Z1, obox:CX,CY,CZ,SX,SY,SZ,AX,AY,AZ (mm, degrees) or mask:FILE (a NIfTI "
                  "image: its voxels >= 0.5, as tckedit reads a mask); repeatable");
  cmd->add_option("--include-ordered", o->include_ordered,
                  "Regions a kept streamline enters in the order given (tckedit -include_ordered); repeatable");
  cmd->add_option("--exclude", o->exclude, "A region no kept streamline has a vertex in; repeatable");
  cmd->add_flag("--ends-only", o->ends_only, "Test only the two end vertices against the regions");
  cmd->add_option("--min-length", o->min_length, "Shortest length kept, mm");
  cmd->add_option("--max-length", o->max_length, "Longest length kept, mm");
  cmd->add_option("--threads", o->threads, "Threads testing the streamlines (0: every core)");
  cmd->add_flag("--force,-f", o->force, "Overwrite the output if it exists");
  cmd->callback([o] { runFilterCommand(*o); });
}

}  // namespace fibscope
