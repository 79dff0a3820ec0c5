// Spline tubes on the command line (issue 15 item 5): `--tubes
// FIBERS|all|filtered` with `--tube-radius MM` (or a radius from the data,
// --tube-radius-from) draws the listed fibers as tubes over the lines,
// depth-composited, by the method of the setting --tube-method.
#pragma once

#include <CLI/CLI.hpp>

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/tractogram.h"
#include "tubes/tube_model.h"

namespace fibscope {

struct TubeCliOptions {
  std::string fibers;  // "" none, "all", "filtered" (the fiber filter's kept ones), or indices and ranges: "0-99,512"
  float radius_mm = 0.5f;
  // The radius from the file's data (issue 15 item 1): a per-point array
  // (trk scalars, TRX dpv) or, failing that, a per-streamline one (trk
  // properties, TRX dps) of that name, or a .tsf file beside a .tck input
  // (its stem names the array); its values mapped linearly from
  // radius_data ("LO,HI"; empty: the selected fibers' finite min and max)
  // onto radius_range ("MIN,MAX" mm), clamped.
  std::string radius_from;
  std::string radius_data;
  std::string radius_range = "0.2,1";
  float resample_tolerance_mm = -1.0f;  // < 0: a twentieth of the radius
  bool dim_rest = false;                // the tube fibers as the selection: highlighted, the rest dimmed
  bool given = false;                   // --tubes was on the command line (even as an empty string)
  float tolerance() const { return resample_tolerance_mm < 0.0f ? radius_mm / 20.0f : resample_tolerance_mm; }
  bool requested() const { return given || !fibers.empty(); }
};

void addTubeCliOptions(CLI::App* cmd, TubeCliOptions& options);

// SVO streamtubes (render's and bench's `--pipeline svo-straight|svo-curved`,
// bench's --compare entries): the octree of the --tubes fibers.
inline constexpr std::string_view kSvoPipelineNames[] = {"svo-straight", "svo-curved"};
// 0 svo-straight, 1 svo-curved, -1 any other pipeline name.
int svoPipelineKind(std::string_view pipeline);
// The tube options an octree is built with: every fiber unless --tubes
// names them, and the fibers' own points unless --tube-tolerance is given
// (resampling fits a Hermite curve, not a polyline; the curved tubes keep
// every point too, so straight and curved tubes share their nodes).
void useSvoTubeDefaults(TubeCliOptions& options);

// --svo-lod-px (render: one value; bench: a comma list, each svo variant
// once per value, side by side): the SVO trace's level of detail
// (SvoTraceOptions::lod_px), pixels in [0, kSvoLodMaxPx], 0 off. Throws
// Error (one line, naming --svo-lod-px) for anything else, an empty list
// included. Safe on untrusted text.
inline constexpr float kSvoLodMaxPx = 64.0f;
inline constexpr std::string_view kSvoLodHelp =
    "Level of detail of the svo pipelines: an octree node smaller than PX pixels stops the ray there, hit by the "
    "node's most referenced segment (depth within the node's diagonal); 0: off";
std::vector<float> parseSvoLodPx(const std::string& text);

// "all" -> every index below `count`; "A-B,C,..." -> those indices, in the
// order given, repeats dropped. Throws Error (one line, naming --tubes) for
// malformed text, a reversed range or an index >= count. Safe on untrusted
// text.
std::vector<uint32_t> parseFiberSelection(const std::string& text, uint64_t count);

// The tube model of the selected fibers of the input (a file, or the
// built-in phantom of `phantom_streamlines` when `path` is empty), read in
// chunks (only the selected fibers are kept in memory); fiber ids are the
// input's streamline indices. Throws Error naming the input or the option,
// also for a radius larger than the selected fibers' extent (the bounding
// box's diagonal): such tubes would only hide the scene.
// `filtered`: the fibers of --tubes filtered (the filter's kept indices),
// used when options.fibers is "filtered".
TubeModel loadTubeModel(const std::string& path, uint64_t phantom_streamlines, const TubeCliOptions& options,
                        TubeBuildStats* stats = nullptr, const std::vector<uint32_t>* filtered = nullptr);

}  // namespace fibscope
