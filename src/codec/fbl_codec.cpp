#include "codec/fbl_codec.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace fibscope {

FblHeaderFields fblHeaderFor(const CodecParams& params) {
  FblHeaderFields f;
  f.codec_version = kFibletCodecVersion;
  f.points_per_fiblet = params.points_per_fiblet;
  f.fiblet_record_bytes = params.recordBytes();
  for (int c = 0; c < 3; ++c) {
    f.translation[c] = double(params.translation[c]);
    f.v[c] = params.v[c];
  }
  f.scale = 1.0 / double(params.scale);
  f.delta = double(params.delta);
  f.delta_mm = params.deltaMm();
  f.alpha = double(params.alpha);
  return f;
}

CodecParams codecParamsFromFbl(const FblHeaderFields& f, const std::string& path) {
  if (f.codec_version != kFibletCodecVersion)
    fail(path, "fiblet encoding version " + std::to_string(f.codec_version) + " (this fibscope reads version " +
                   std::to_string(kFibletCodecVersion) + ")");
  CodecParams p;
  p.points_per_fiblet = f.points_per_fiblet;
  // Range checks before the float conversions (a double beyond float range
  // converts to inf, which validateCodecParams rejects; NaN stays NaN).
  if (!(std::isfinite(f.scale) && f.scale > 0)) fail(path, "header: scale must be finite and > 0");
  p.scale = float(1.0 / f.scale);
  p.delta = float(f.delta);
  p.alpha = float(f.alpha);
  for (int c = 0; c < 3; ++c) {
    p.translation[c] = float(f.translation[c]);
    p.v[c] = f.v[c];
  }
  try {
    validateCodecParams(p);
  } catch (const Error& e) {
    fail(path, std::string("header: ") + e.what());
  }
  if (f.fiblet_record_bytes != p.recordBytes())
    fail(path, "header: fiblet records of " + std::to_string(f.fiblet_record_bytes) + " bytes, expected " +
                   std::to_string(p.recordBytes()) + " for " + std::to_string(p.points_per_fiblet) + " points");
  return p;
}

CodecParams roundTripThroughFbl(const CodecParams& params) {
  CodecParams p = params;
  p.scale = float(1.0 / (1.0 / double(params.scale)));
  return p;
}

namespace {

nlohmann::json arraysJson(const std::vector<DataArray>& arrays) {
  nlohmann::json j = nlohmann::json::array();
  for (const DataArray& a : arrays) j.push_back({{"name", a.name}, {"components", a.components}, {"dtype", a.dtype}});
  return j;
}

}  // namespace

std::string fblSourceJson(const TractogramHeader& h, const std::vector<DataArray>& dropped_per_point) {
  nlohmann::json j;
  j["path"] = h.path;
  j["format"] = h.format;
  j["file_bytes"] = h.file_bytes;
  j["declared_streamlines"] = h.declared_streamlines;
  j["declared_points"] = h.declared_points;
  if (h.space.known) {
    j["space"] = {{"voxel_to_rasmm", h.space.voxel_to_rasmm},
                  {"dimensions", h.space.dimensions},
                  {"voxel_sizes", h.space.voxel_sizes},
                  {"voxel_order", h.space.voxel_order}};
  }
  nlohmann::json properties = nlohmann::json::array();
  for (const auto& [key, value] : h.properties) properties.push_back({key, value});
  j["properties"] = properties;
  j["per_streamline"] = arraysJson(h.per_streamline);
  j["per_point"] = arraysJson(h.per_point);
  j["dropped_per_point"] = arraysJson(dropped_per_point);
  // Dumped with replacement of invalid UTF-8 (tck keys are raw bytes).
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

TractogramHeader headerFromFblSource(std::string_view text, const std::string& fbl_path) {
  TractogramHeader h;
  h.path = fbl_path;
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.begin(), text.end());
    if (!j.is_object()) fail(fbl_path, "section source: JSON is not an object");
    h.format = j.value("format", std::string());
    if (j.contains("space")) {
      const auto& s = j.at("space");
      h.space.known = true;
      h.space.voxel_to_rasmm = s.at("voxel_to_rasmm").get<std::array<float, 16>>();
      h.space.dimensions = s.at("dimensions").get<std::array<int32_t, 3>>();
      h.space.voxel_sizes = s.at("voxel_sizes").get<std::array<float, 3>>();
      h.space.voxel_order = s.at("voxel_order").get<std::string>();
    }
    if (j.contains("properties"))
      for (const auto& kv : j.at("properties"))
        h.properties.emplace_back(kv.at(0).get<std::string>(), kv.at(1).get<std::string>());
    const auto arrays = [&](const char* key, std::vector<DataArray>& out) {
      if (!j.contains(key)) return;
      for (const auto& a : j.at(key)) {
        DataArray array;
        array.name = a.at("name").get<std::string>();
        array.components = a.at("components").get<uint32_t>();
        array.dtype = a.at("dtype").get<std::string>();
        if (array.components == 0 || array.components > 4096)
          // The name as a JSON string: escaped, so the message stays one line.
          fail(fbl_path, "section source: array " +
                             a.at("name").dump(-1, ' ', false, nlohmann::json::error_handler_t::replace) + " has " +
                             std::to_string(array.components) + " components");
        out.push_back(std::move(array));
      }
    };
    arrays("per_streamline", h.per_streamline);
    // Files written before per-point arrays were stored list them as
    // "dropped_per_point": those are not read back.
    arrays("per_point", h.per_point);
  } catch (const nlohmann::json::exception& e) {
    // nlohmann messages are one line; keep them short.
    fail(fbl_path, std::string("section source: ") + e.what());
  }
  return h;
}

}  // namespace fibscope
