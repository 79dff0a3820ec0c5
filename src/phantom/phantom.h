// Brain-like tractogram phantom (DESIGN.md section 7).
//
// The phantom is a set of white-matter bundles inside a brain-sized
// ellipsoid in RAS+ millimetres: corpus callosum, left/right corticospinal
// tracts, arcuate fasciculi, cingula, IFOF and ILF, and short U-fibers under
// the cortex. Each bundle is a family of smooth guide curves (fanning where
// the anatomy fans); each fiber is walked along its guide by a tracker that
// has the statistics of probabilistic tractography output:
//   - every segment is exactly `step_mm` long (to float precision);
//   - consecutive segments turn by at most `max_angle_deg`, most turns far
//     below it (small random jitter on top of the smooth bundle curvature);
//   - lengths lie in [min_length_mm, max_length_mm];
//   - every point lies inside the ellipsoid (fibers end at its surface).
// Streamline i is a pure function of (options, seed, i): the output does not
// depend on the thread count or on how it is read in chunks.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "core/tractogram.h"
#include "io/reader.h"

namespace fibscope {

// Bundles, in the order of their index in the per-streamline "bundle" array.
enum class PhantomBundle : uint8_t {
  CorpusCallosum,
  CstLeft,
  CstRight,
  ArcuateLeft,
  ArcuateRight,
  CingulumLeft,
  CingulumRight,
  IfofLeft,
  IfofRight,
  IlfLeft,
  IlfRight,
  UFibers,
  // Fibers throughout the white matter, outside the named bundles (see
  // phantom_anatomy.cpp): left-right, front-back and bottom-top families.
  WhiteMatterCommissural,
  WhiteMatterAssociation,
  WhiteMatterProjection,
};
inline constexpr size_t kPhantomBundleCount = 15;

inline constexpr unsigned kPhantomMaxRetries = 16;

// Semi-axes of the brain ellipsoid (left-right, anterior-posterior,
// inferior-superior), centred at the origin: 140 x 170 x 120 mm.
inline constexpr std::array<double, 3> kPhantomSemiAxesMm = {70.0, 85.0, 60.0};

// "corpus_callosum", "cst_left", "cst_right", "arcuate_left", ...,
// "u_fibers", indexed by PhantomBundle.
const std::array<std::string_view, kPhantomBundleCount>& phantomBundleNames();
// Index of a bundle name, or -1 when there is none of that name.
int phantomBundleIndex(std::string_view name);
// Relative share of fibers per bundle used when PhantomOptions::bundle_weights
// is empty: the whole-brain mix, the white-matter families (wm_*) at 2.1,
// 2.1 and 1.8 beside the named bundles' shares (namedBundlePhantomWeights,
// together 1), so 87 % of the fibers fill the white matter and the phantom
// fills and occludes like whole-brain tracking (MRtrix3 iFOD1 on
// scripts/make_tckgen_250mb.sh's field: docs/BENCHMARKS.md, "Phantom
// density").
const std::array<double, kPhantomBundleCount>& defaultPhantomBundleWeights();
// The named bundles alone (the wm_* families 0): the corpus callosum and
// U-fibers dominate; the left arcuate is larger than the right.
const std::array<double, kPhantomBundleCount>& namedBundlePhantomWeights();

struct PhantomOptions {
  uint64_t streamlines = 10000;
  double step_mm = 0.1;
  // 15 degrees per step is MRtrix3's default for iFOD1, the tracker that made
  // the fiblets paper's 0.1 mm and 0.05 mm datasets (its default step is
  // 0.1 x voxel size). At 0.1 mm it bounds the radius of curvature at
  // 0.38 mm, far below anatomical curvature, so the cap shapes only the tail
  // of the jitter, as in real output.
  double max_angle_deg = 15.0;
  uint64_t seed = 1;
  double min_length_mm = 20.0;
  double max_length_mm = 250.0;
  unsigned threads = 0;  // 0 = std::thread::hardware_concurrency()
  // Scale of the tracker's random direction noise: 1 looks like
  // probabilistic (iFOD1-like) output, 0 gives smooth deterministic-looking
  // fibers. The noise per step scales with sqrt(step), so the shape of a
  // fiber does not depend on the step size.
  double jitter = 1.0;
  // Relative share of fibers per bundle (kPhantomBundleCount values >= 0,
  // not all 0), indexed by PhantomBundle; empty = defaultPhantomBundleWeights().
  std::vector<double> bundle_weights;
  // Cross sections of the named bundles (all but the cingulum) are the
  // anatomy table's radii times this: tracked bundles are 2.5 times as
  // thick as the anatomy table's cores in the whole-brain mix.
  double bundle_radius_scale = 2.5;
};

// The named bundles alone and thin (namedBundlePhantomWeights, radius scale
// 1): few, dense, well separated bundles, each fiber easy to tell apart;
// the layout tests of picking, cuts and dissection aim at. Sets
// bundle_weights and bundle_radius_scale of `options`.
void applyNamedBundlesPhantomMix(PhantomOptions& options);

// Throws Error ("phantom: <option> ...", one line) when an option is out of
// range: step_mm outside [0.005, 10], max_angle_deg outside [1, 90],
// bundle_radius_scale outside [0.25, 4],
// min_length_mm outside [0, 150] (no phantom bundle is longer than about
// 170 mm), max_length_mm below min_length_mm or above 10000, no whole number
// of steps between the two lengths, jitter outside [0, 4], threads above 1024,
// or bad bundle weights.
void validatePhantomOptions(const PhantomOptions& options);

// Parses a bundle mix "corpus_callosum=2,u_fibers=0,..." into a full weight
// vector: named bundles take the given weights, the others keep their
// default weights. Throws Error naming the bad entry for unknown names,
// missing '=', or weights that are not finite numbers >= 0.
// `base` (kPhantomBundleCount weights) replaces the defaults when given.
std::vector<double> parsePhantomBundleMix(const std::string& text, const std::vector<double>& base = {});

// Reusable per-thread buffers of PhantomGenerator::generate, so that
// generation does not allocate per streamline once they have grown.
struct PhantomScratch {
  PhantomScratch();
  ~PhantomScratch();
  PhantomScratch(PhantomScratch&&) noexcept;
  PhantomScratch& operator=(PhantomScratch&&) noexcept;
  struct Buffers;
  std::unique_ptr<Buffers> buffers;
};

// The deterministic per-streamline generator behind openPhantom. Immutable
// after construction, so one generator may be shared by many threads.
class PhantomGenerator {
 public:
  // Validates `options` (see validatePhantomOptions).
  explicit PhantomGenerator(const PhantomOptions& options);

  const PhantomOptions& options() const { return options_; }

  // Appends the points (x, y, z floats, RAS+ mm) of streamline `index` to
  // `xyz` and returns its bundle. Depends only on the options and `index`
  // (any index, also beyond options().streamlines). `retries`, when given,
  // receives how many drawn fibers were discarded first because they could
  // not reach min_length_mm (a guide too short, or the fiber left the
  // ellipsoid early; about 1% with the defaults). kPhantomMaxRetries means
  // none succeeded and a straight anterior-posterior fiber through the
  // centre was returned instead, which keeps every guarantee; it only
  // happens when the weights leave no bundle long enough for min_length_mm.
  PhantomBundle generate(uint64_t index, std::vector<float>& xyz, PhantomScratch& scratch,
                         unsigned* retries = nullptr) const;

  // Appends streamlines [first, first + count) to `out`, with their bundle
  // indices in a per-streamline array "bundle" (created when `out` has no
  // per-streamline array yet; it must otherwise be out.per_streamline[0]).
  void generateRange(uint64_t first, uint64_t count, Tractogram& out, PhantomScratch& scratch) const;

 private:
  PhantomOptions options_;
  std::array<double, kPhantomBundleCount> cumulative_weights_{};
  double step_ = 0.1;
  uint64_t min_steps_ = 0, max_steps_ = 0;
  struct Tracker;
  std::shared_ptr<const Tracker> tracker_;
};

// A phantom as a streaming reader: streamlines are generated on the fly, a
// chunk at a time, in parallel on options.threads threads (the next chunk is
// generated while the caller consumes the current one), so a 10 M-fiber,
// 8 G-segment phantom streams to a writer in bounded memory. The header has
// format "phantom", declared_streamlines = options.streamlines, a per-
// streamline array "bundle" (dtype uint8, values = PhantomBundle index), a
// 1 mm voxel grid covering the ellipsoid as its space, and the options and
// bundle names in its properties (MRtrix-style keys: method, step_size,
// max_angle, min_dist, max_dist; then phantom_seed, phantom_jitter,
// phantom_bundles, phantom_bundle_weights). bytesRead() counts the float32
// position bytes handed out. Throws Error for invalid options.
std::unique_ptr<TractogramReader> openPhantom(const PhantomOptions& options);

}  // namespace fibscope
