#include "codec/compressor.h"

#include <chrono>
#include <cmath>
#include <deque>
#include <filesystem>
#include <future>
#include <utility>

#include "codec/fbl_codec.h"
#include "codec/fbl_file.h"
#include "codec/fbl_reader.h"
#include "core/error.h"
#include "core/output_file.h"
#include "core/spill_file.h"
#include "core/thread_pool.h"

namespace fibscope {

namespace {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// One chunk of fibers on its way through a worker.
struct ChunkJob {
  std::string source;  // the input path, for messages
  Tractogram input;
  EncodedFiblets fiblets;      // fiblet indices local to the chunk (fiblet_base 0)
  std::vector<float> lengths;  // arc length of each input fiber, mm
  uint64_t encoded_points = 0;
  ResampleReport resample;
  // With resampling: the input's per-point arrays at the resampled points
  // (resampleToStep's interpolation), in the input's order; else empty (the
  // input's own values are the encoded points').
  std::vector<DataArray> resampled_per_point;
};

void encodeChunk(FibletEncoder& encoder, ChunkJob& job, bool resample, double delta_mm) {
  const Tractogram& in = job.input;
  // What openFbl accepts: one fiber is decoded whole into memory.
  const auto checkLengths = [&](const Tractogram& t) {
    for (size_t s = 0; s < t.streamlineCount(); ++s)
      if (t.pointsIn(s) > kFblMaxFiberPoints)
        fail(job.source, "a streamline has " + std::to_string(t.pointsIn(s)) + " points, more than the " +
                             std::to_string(kFblMaxFiberPoints) + " a .fbl fiber may hold");
  };
  job.lengths.resize(in.streamlineCount());
  for (size_t s = 0; s < in.streamlineCount(); ++s)
    job.lengths[s] = polylineLength(in.point(in.offsets[s]), in.pointsIn(s));
  job.fiblets.record_bytes = encoder.decoder().params().recordBytes();
  if (resample) {
    Tractogram resampled = resampleToStep(in, delta_mm, &job.resample);
    checkLengths(resampled);
    encoder.encode(resampled, job.fiblets);
    job.encoded_points = resampled.pointCount();
    job.resampled_per_point = std::move(resampled.per_point);
  } else {
    checkLengths(in);
    encoder.encode(in, job.fiblets);
    job.encoded_points = in.pointCount();
  }
}

// Whether `name` can be a section name "dps/<name>" or "dpv/<name>"
// (FblWriter's rules; both prefixes are 4 bytes).
bool storableArrayName(const std::string& name) {
  static_assert(kFblSectionDpsPrefix.size() == kFblSectionDpvPrefix.size());
  if (name.empty() || name.size() + kFblSectionDpsPrefix.size() > 47) return false;
  for (unsigned char c : name)
    if (c < 0x20 || c == 0x7f) return false;
  return true;
}

uint64_t inputBytes(const TractogramHeader& header) {
  if (header.file_bytes > 0) return header.file_bytes;
  std::error_code ec;
  const std::filesystem::path path(header.path);
  if (std::filesystem::is_regular_file(path, ec)) return std::filesystem::file_size(path, ec);
  uint64_t total = 0;  // a TRX directory
  if (std::filesystem::is_directory(path, ec))
    for (const auto& entry : std::filesystem::recursive_directory_iterator(path, ec))
      if (entry.is_regular_file(ec)) total += entry.file_size(ec);
  return total;
}

std::string percent(double fraction) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f%%", 100 * fraction);
  return text;
}

}  // namespace

CompressReport compressTractogram(const ReaderFactory& open_input, const std::string& output,
                                  const CompressOptions& options) {
  // Refuse before reading anything: never overwrite silently.
  checkOverwrite(output, options.overwrite);
  CompressReport report;
  report.output = output;
  report.mode = options.encode.mode;
  report.resampled = options.resample;

  // Pass 1: parameters.
  const auto analyse_start = Clock::now();
  std::unique_ptr<TractogramReader> reader = open_input();
  const TractogramHeader header = reader->header();
  report.input = header.path;
  report.input_format = header.format;
  report.input_bytes = inputBytes(header);
  CodecParamEstimator estimator(options.params);
  {
    Progress progress("analysing", double(report.input_bytes), "bytes", options.terminal_progress,
                      options.progress_sink);
    Tractogram chunk;
    chunk.positions.reserve(3 * (options.chunk_points + options.chunk_points / 4));
    while (reader->read(chunk, options.chunk_points)) {
      estimator.add(chunk);
      progress.set(double(reader->bytesRead()));
    }
    progress.finish();
  }
  report.warnings = reader->warnings();
  try {
    report.analysis = estimator.summary(options.encode.step_tolerance);
  } catch (const Error& e) {
    fail(header.path, e.what());
  }
  const CodecParams params = roundTripThroughFbl(report.analysis.params);
  report.analysis.params = params;
  if (!options.resample && report.analysis.steps_off_fraction > 0.05)
    report.warnings.push_back(header.path + ": " + percent(report.analysis.steps_off_fraction) +
                              " of the steps differ from the step " + std::to_string(params.deltaMm()) +
                              " mm by more than " + percent(options.encode.step_tolerance) +
                              "; each starts a new fiblet (use --resample to resample fibers to the step)");
  report.analyse_seconds = secondsSince(analyse_start);

  // What the .fbl keeps of the input besides the points.
  TractogramHeader stored = header;
  stored.per_streamline.clear();
  std::vector<size_t> stored_arrays;  // indices into the chunks' per_streamline
  for (size_t a = 0; a < header.per_streamline.size(); ++a) {
    if (storableArrayName(header.per_streamline[a].name)) {
      stored_arrays.push_back(a);
      stored.per_streamline.push_back(header.per_streamline[a]);
    } else {
      report.dropped.push_back("per-streamline array \"" + header.per_streamline[a].name +
                               "\" (name unusable as a section name)");
    }
  }
  stored.per_point.clear();
  std::vector<size_t> stored_point_arrays;  // indices into the chunks' per_point
  std::vector<DataArray> dropped_point_arrays;
  for (size_t a = 0; a < header.per_point.size(); ++a) {
    if (storableArrayName(header.per_point[a].name)) {
      stored_point_arrays.push_back(a);
      stored.per_point.push_back(header.per_point[a]);
    } else {
      dropped_point_arrays.push_back(header.per_point[a]);
      report.dropped.push_back("per-point array \"" + header.per_point[a].name +
                               "\" (name unusable as a section name)");
    }
  }
  if (!header.groups.empty())
    report.dropped.push_back(std::to_string(header.groups.size()) + " TRX groups (not stored in .fbl version 1)");

  // Pass 2: encode.
  const auto encode_start = Clock::now();
  reader = open_input();
  if (reader->header().per_streamline.size() != header.per_streamline.size() ||
      reader->header().per_point.size() != header.per_point.size())
    fail(header.path, "changed between the two passes of compression");
  std::string directory = std::filesystem::path(output).parent_path().string();
  if (directory.empty()) directory = ".";
  // The section table holds exactly the sections written (fiblets, two
  // fiber tables, the per-fiber arrays, with per-point arrays their table
  // of first points and the arrays, source): on small files a spare table
  // is a visible part of the bytes per point.
  const bool point_data = !stored_point_arrays.empty();
  FblWriter writer(output, fblHeaderFor(params), options.overwrite,
                   uint32_t(4 + stored_arrays.size() + (point_data ? 1 + stored_point_arrays.size() : 0)));
  SpillFile first_fiblets(directory, "fiber table");
  SpillFile lengths(directory, "fiber lengths");
  std::vector<SpillFile> arrays;
  for (size_t a = 0; a < stored_arrays.size(); ++a) arrays.emplace_back(directory, "per-streamline data");
  SpillFile first_points(directory, "fiber point table");
  std::vector<SpillFile> point_arrays;
  for (size_t a = 0; a < stored_point_arrays.size(); ++a) point_arrays.emplace_back(directory, "per-point data");
  uint64_t point_base = 0;  // encoded points of the chunks written
  std::vector<uint64_t> point_firsts;

  const unsigned threads = options.threads ? options.threads : ThreadPool::hardwareThreads();
  report.threads = threads;
  std::vector<std::unique_ptr<FibletEncoder>> encoders;
  std::vector<CodecErrorMeter> meters(threads);
  for (unsigned w = 0; w < threads; ++w) {
    encoders.push_back(std::make_unique<FibletEncoder>(params, options.encode));
    encoders.back()->setErrorMeter(&meters[w]);
  }
  const double delta_mm = params.deltaMm();
  writer.beginSection(std::string(kFblSectionFiblets), FblDType::kUint32);
  uint64_t fiblet_base = 0, input_points = 0;
  std::vector<uint64_t> firsts;
  {
    // Declared after everything its jobs touch, so that on an exception it
    // finishes and joins them before those go away.
    ThreadPool pool(threads);
    Progress progress("compressing", double(report.analysis.points), "points", options.terminal_progress,
                      options.progress_sink);
    std::deque<std::pair<std::future<void>, std::shared_ptr<ChunkJob>>> in_flight;
    // Written jobs are reused: their buffers keep their capacity, so the
    // steady state allocates nothing (fresh 10 MB buffers per chunk cost
    // page faults and copies worth a tenth of the time).
    std::vector<std::shared_ptr<ChunkJob>> spare;
    const auto writeOldest = [&] {
      auto [done, job] = std::move(in_flight.front());
      in_flight.pop_front();
      done.get();  // rethrows the worker's exception
      const EncodedFiblets& f = job->fiblets;
      writer.append(f.bytes.data(), f.bytes.size());
      firsts.resize(f.fiber_first_fiblet.size());
      for (size_t i = 0; i < firsts.size(); ++i) firsts[i] = fiblet_base + f.fiber_first_fiblet[i];
      first_fiblets.write(firsts.data(), firsts.size() * sizeof(uint64_t));
      lengths.write(job->lengths.data(), job->lengths.size() * sizeof(float));
      for (size_t a = 0; a < stored_arrays.size(); ++a) {
        const std::vector<float>& values = job->input.per_streamline[stored_arrays[a]].values;
        arrays[a].write(values.data(), values.size() * sizeof(float));
      }
      if (point_data) {
        point_firsts.resize(f.fiber_points.size());
        for (size_t i = 0; i < point_firsts.size(); ++i) {
          point_firsts[i] = point_base;
          point_base += f.fiber_points[i];
        }
        first_points.write(point_firsts.data(), point_firsts.size() * sizeof(uint64_t));
        const std::vector<DataArray>& per_point =
            options.resample ? job->resampled_per_point : job->input.per_point;
        for (size_t a = 0; a < stored_point_arrays.size(); ++a) {
          const DataArray& array = per_point.at(stored_point_arrays[a]);
          if (array.values.size() != job->encoded_points * array.components)
            fail(header.path, "per-point array \"" + array.name + "\" holds " + std::to_string(array.values.size()) +
                                  " values for " + std::to_string(job->encoded_points) + " points");
          point_arrays[a].write(array.values.data(), array.values.size() * sizeof(float));
        }
      }
      fiblet_base += f.fibletCount();
      report.fibers += job->input.streamlineCount();
      report.points += job->encoded_points;
      input_points += job->input.pointCount();
      if (options.resample) report.resample.merge(job->resample);
      progress.add(double(job->input.pointCount()));
      job->fiblets.bytes.clear();
      job->fiblets.fiber_first_fiblet.clear();
      job->fiblets.fiber_points.clear();
      job->resample = {};
      job->resampled_per_point.clear();
      spare.push_back(std::move(job));
    };
    for (;;) {
      std::shared_ptr<ChunkJob> job;
      if (spare.empty()) {
        job = std::make_shared<ChunkJob>();
        job->source = header.path;
        // A chunk ends with a whole streamline, a little past chunk_points.
        job->input.positions.reserve(3 * (options.chunk_points + options.chunk_points / 4));
      } else {
        job = std::move(spare.back());
        spare.pop_back();
      }
      if (!reader->read(job->input, options.chunk_points)) break;
      const bool resample = options.resample;
      in_flight.emplace_back(pool.submit([&encoders, job, resample, delta_mm](unsigned worker) {
        encodeChunk(*encoders[worker], *job, resample, delta_mm);
      }),
                             job);
      // Read ahead by one chunk per worker plus one: enough to keep every
      // worker busy, bounded whatever the input size.
      if (in_flight.size() > threads + 1) writeOldest();
    }
    while (!in_flight.empty()) writeOldest();
    progress.finish();
  }
  writer.endSection();
  if (input_points != report.analysis.points)
    fail(header.path, "changed between the two passes of compression (" + std::to_string(report.analysis.points) +
                          " points, then " + std::to_string(input_points) + ")");
  for (const std::string& w : reader->warnings())
    if (std::find(report.warnings.begin(), report.warnings.end(), w) == report.warnings.end())
      report.warnings.push_back(w);

  // The per-fiber sections, from the scratch files.
  first_fiblets.write(&fiblet_base, sizeof fiblet_base);  // the end of the last fiber
  const auto copySection = [&](SpillFile& spill, const std::string& name, FblDType dtype, uint32_t components) {
    writer.beginSection(name, dtype, components);
    spill.readBack([&](const uint8_t* data, size_t bytes) { writer.append(data, bytes); });
    writer.endSection();
  };
  copySection(first_fiblets, std::string(kFblSectionFiberFirstFiblet), FblDType::kUint64, 1);
  copySection(lengths, std::string(kFblSectionFiberLength), FblDType::kFloat32, 1);
  for (size_t a = 0; a < stored_arrays.size(); ++a) {
    const DataArray& array = header.per_streamline[stored_arrays[a]];
    copySection(arrays[a], std::string(kFblSectionDpsPrefix) + array.name, FblDType::kFloat32, array.components);
  }
  if (point_data) {
    first_points.write(&point_base, sizeof point_base);  // the end of the last fiber
    copySection(first_points, std::string(kFblSectionFiberFirstPoint), FblDType::kUint64, 1);
    for (size_t a = 0; a < stored_point_arrays.size(); ++a) {
      const DataArray& array = header.per_point[stored_point_arrays[a]];
      copySection(point_arrays[a], std::string(kFblSectionDpvPrefix) + array.name, FblDType::kFloat32,
                  array.components);
    }
  }
  const std::string source = fblSourceJson(stored, dropped_point_arrays);
  writer.writeSection({std::string(kFblSectionSource), FblDType::kUtf8, 1}, source.data(), source.size());

  FblHeaderFields& fields = writer.fields();
  fields.fiber_count = report.fibers;
  fields.fiblet_count = fiblet_base;
  fields.point_count = report.points;
  writer.finish();
  report.encode_seconds = secondsSince(encode_start);

  report.fiblets = fiblet_base;
  for (const FblSection& s : writer.sections())
    if (s.name == kFblSectionFiblets) report.fiblet_bytes = s.bytes;
  std::error_code ec;
  report.output_bytes = std::filesystem::file_size(output, ec);
  for (unsigned w = 0; w < threads; ++w) {
    report.encode.merge(encoders[w]->report());
    if (w > 0) meters[0].merge(meters[w]);
  }
  report.error = meters[0].stats();
  report.analysis.max_turn_deg = std::max(report.analysis.max_turn_deg, report.encode.maxTurnDegrees());
  return report;
}

}  // namespace fibscope
