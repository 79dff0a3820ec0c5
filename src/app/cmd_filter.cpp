// `fibscope filter IN OUT`: the streamlines that criteria keep (regions of
// interest, lengths), as MRtrix3's tckedit keeps them, from any format to
// any format, streamed, on every core, with how many each criterion dropped.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "app/commands.h"
#include "app/criteria_options.h"
#include "app/open_input.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/progress.h"
#include "io/writer.h"
#include "select/filter_run.h"
#include "select/scalar_range.h"

namespace fibscope {
namespace {

struct FilterOptions {
  std::string input, output;
  CriteriaCliOptions criteria;
  bool force = false;
  unsigned threads = 0;
};

std::string percent(uint64_t part, uint64_t whole) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %%", whole ? 100.0 * double(part) / double(whole) : 0.0);
  return buf;
}

void runFilterCommand(const FilterOptions& o) {
  const CliCriteria named = criteriaFrom(o.criteria);
  const FilterCriteria& criteria = named.criteria;
  // Refuse before reading anything: never overwrite silently.
  checkOverwrite(o.output, o.force);
  const auto start = std::chrono::steady_clock::now();
  auto reader = openInput(o.input);
  const FiberFilter filter(criteria, headerStepSize(reader->header()));
  // Every scalar range's array in the input, before the output is made.
  resolveScalarColumns(criteria.scalar_ranges, reader->header().per_streamline, o.input);
  WriterOptions wo;
  wo.overwrite = o.force;
  auto writer = createTractogramWriter(o.output, reader->header(), wo);
  std::error_code ec;
  const auto bytes = std::filesystem::is_regular_file(o.input, ec) ? std::filesystem::file_size(o.input, ec) : 0;
  Progress progress("filtering", double(bytes), "bytes");
  const auto report_progress = [&](uint64_t done) { progress.set(double(done)); };
  // A .tck is tested in place (no copy of what is dropped); a file that
  // turns out damaged on the way is read again by the reader, into a new
  // output, so its messages are the reader's.
  std::vector<std::string> warnings = reader->warnings();
  std::optional<FilterReport> in_place;
  if (reader->header().format == "tck" && reader->header().per_point.empty()) {
    in_place = runTckFilterInPlace(o.input, *writer, filter, warnings, o.threads, report_progress);
    if (!in_place) {
      writer.reset();  // its temporary file goes with it
      writer = createTractogramWriter(o.output, reader->header(), wo);
    }
  }
  const FilterReport r = in_place ? *in_place : runFilter(*reader, *writer, filter, o.threads, report_progress);
  if (!in_place) warnings = reader->warnings();
  writer->finish();
  progress.finish();
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  for (const auto& w : warnings) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
  for (const auto& w : writer->warnings()) std::fprintf(stderr, "fibscope: warning: %s\n", w.c_str());
  std::printf("wrote %s: %llu of %llu streamlines kept (%s), %llu points, %.2f s\n", o.output.c_str(),
              static_cast<unsigned long long>(r.kept), static_cast<unsigned long long>(r.streamlines),
              percent(r.kept, r.streamlines).c_str(), static_cast<unsigned long long>(r.kept_points), seconds);
  if (r.groups_kept + r.groups_dropped > 0)
    std::printf("  groups: %zu kept with their kept members renumbered, %zu dropped (no member kept)\n", r.groups_kept,
                r.groups_dropped);
  auto dropped = [&](const std::string& what, uint64_t n) {
    std::printf("  dropped %llu (%s): %s\n", static_cast<unsigned long long>(n), percent(n, r.streamlines).c_str(),
                what.c_str());
  };
  if (!std::isnan(criteria.min_length_mm) || !std::isnan(criteria.max_length_mm) || r.by_length > 0)
    dropped("length", r.by_length);
  for (size_t i = 0; i < r.by_scalar.size(); ++i) dropped(scalarRangeOutside(criteria.scalar_ranges[i]), r.by_scalar[i]);
  for (size_t i = 0; i < r.by_exclude.size(); ++i) dropped("entered " + named.exclude_names[i], r.by_exclude[i]);
  for (size_t i = 0; i < r.by_include.size(); ++i) dropped("missed " + named.include_names[i], r.by_include[i]);
  if (!criteria.include_ordered.empty()) dropped("missed the --include-ordered regions or their order", r.by_order);
  if (criteria.distance_zone && !std::isnan(criteria.max_distance_mm))
    dropped("farther than --max-distance from --distance-to", r.by_distance);
}

}  // namespace

void addFilterCommand(CLI::App& app) {
  auto o = std::make_shared<FilterOptions>();
  CLI::App* cmd = app.add_subcommand(
      "filter", "Keep the streamlines that pass regions of interest, length limits and per-streamline scalar ranges (regions and lengths as MRtrix3's tckedit)");
  cmd->add_option("input", o->input, "Input tractogram (.tck .trk .trk.gz .tt.gz .trx .vtk .vtp .fbl)")->required();
  cmd->add_option("output", o->output, "Output tractogram (.tck .trk .trx)")->required();
  addCriteriaCliOptions(cmd, o->criteria);
  cmd->add_option("--threads", o->threads, "Threads testing the streamlines (0: every core)");
  cmd->add_flag("--force,-f", o->force, "Overwrite the output if it exists");
  cmd->callback([o] { runFilterCommand(*o); });
}

}  // namespace fibscope
