// Viewer scripts: a text file, one command per line, '#' starts a comment,
// run between frames through the same actions as the mouse, keys and panels
// (viewer_actions.h):
//   orbit DX DY | pan DX DY     (window pixels, as a drag)
//   dolly STEPS                 (wheel steps, + = closer)
//   view sagittal|coronal|axial|reset
//   fov DEG                     (10 to 90)
//   set KEY VALUE               (applySetting)
//   wait N                      (frames, 1 to 100000)
//   screenshot OUT.png [WxH]    (WxH: the scene alone at that size)
//   open PATH                   (loads on the worker; frames go on meanwhile)
//   wait-loaded                 (holds until no load is queued or running)
//   model N show|hide|activate  (model N of the list, 0 = the first opened)
//   pick X Y [add]              (window pixels of the last frame; add: ctrl-click)
//   clear-selection
//   export-selection OUT.tck    (the selected fibers of one model: ViewerSelection::exportTck)
//   expect-selected N           (the run fails naming the line unless N are selected)
//   resize W H                 (the window, or the offscreen image, in pixels)
//   anatomy FILE.nii[.gz]       (the anatomical image shown as slices, read while frames go on; the
//                               script goes on once it is shown or refused; viewer_anatomy.h)
//   tubes selection|filtered|both|all|off [RADIUS_MM] [from=ARRAY|from=] [range=MIN,MAX]
//         [svo=straight|curved|off] [voxel=MM] [lod=PX]
//                              (those fibers as spline tubes, viewer_tubes.h; all: every fiber of the visible
//                              models; from=: the radius from a per-fiber array mapped onto range mm, from= alone:
//                              constant again; svo=: drawn as SVO streamtubes instead, voxel= the octree's voxel,
//                              0: from the data, lod= the octree trace's level of detail in pixels (0: off,
//                              the exact walk); the script goes on once they are built; the spline method is
//                              `set tube-method compute|raycast|tess`)
// the virtual dissection (dissection.h, viewer_dissection.h):
//   roi-add NAME include|exclude|include_ordered SPEC   (select/region.h's SPEC; a new NAME)
//   roi-place X Y              (a sphere on the fiber drawn at that window pixel: the right click)
//   roi-remove NAME | roi-enable NAME on|off
//   ends-only on|off | length MIN MAX   (mm, '-': no limit)
//   fiber-scalar NAME[K] MIN MAX       (a per-fiber scalar's range, '-': open; replaces NAME[K]'s)
//   fiber-scalar-clear                 (no scalar ranges)
//   clip-plane-add PX,PY,PZ,NX,NY,NZ    (keeps the side the normal points to) | clip-plane-clear
//   cut-mesh-add SPEC:inside|outside    (an OBJ path or box:/obox:/sphere:, select/cut_mesh.h; hides what lies
//                              inside or outside it; a file that cannot be read is one line, nothing added)
//   cut-mesh-clear
//   slab MM                    (around the focal plane; 0: none) | dropped hide|dim
//   roi-save FILE.json | roi-load FILE.json   (a load that fails keeps the state, the error is shown)
//   export-kept OUT.tck|.trk|.trx  (the active model's kept fibers, as `fibscope filter`; holds until written)
//   expect-kept N              (the run fails naming the line unless the filter keeps N fibers)
// bundling (viewer_bundling.h):
//   bundle [KEY=VALUE ...]     (the active model on a worker; KEY: radius iterations voxel step smoothing
//                              relaxation decay advection anisotropy mode=isotropic|anisotropic
//                              structure=0|1 structure-power structure-scale, as
//                              `fibscope bundle`'s options; 0 for voxel or step: the default fraction)
//   wait-bundle                (holds until the bundled copy is a model: shown and active, the source hidden)
//   show-model N               (model N shown and active, the others hidden: original / bundled)
//   save-model N PATH          (.tck .trk .trx .fbl, as `fibscope bundle` writes; an existing PATH is refused)
//   quit
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "app/viewer/viewer_actions.h"

namespace fibscope {

struct WaitFrames {
  uint32_t frames = 1;
};

struct WaitLoaded {};

// Follows export-kept: holds until the export is written.
struct WaitExported {};

// Follows bundle (or stands alone): holds until the bundled copy is loaded.
struct WaitBundled {};

struct ScriptStep {
  int line = 0;  // 1-based, for messages
  std::variant<ViewerAction, WaitFrames, WaitLoaded, WaitExported, WaitBundled> command;
};

// Parses a whole script. `path` only names the script in messages. Throws
// Error "PATH:LINE: ..." (one line) at the first malformed line. Pure: no
// files, no GPU; safe on untrusted text.
std::vector<ScriptStep> parseScript(std::string_view text, const std::string& path);
// Reads and parses the file (Error naming it when it cannot be read).
std::vector<ScriptStep> loadScript(const std::string& path);

// Steps through a parsed script, one frame at a time.
class ScriptRunner {
 public:
  ScriptRunner() = default;
  explicit ScriptRunner(std::vector<ScriptStep> steps) : steps_(std::move(steps)) {}

  // The actions to apply before the next frame: every command up to the
  // next `wait` (which then holds for its frames), `wait-loaded` (which
  // holds while `loading`) or export-kept (holds while `exporting`), or
  // none while waiting.
  // wait-bundle holds while `bundling`.
  std::vector<ViewerAction> nextFrame(bool loading = false, bool exporting = false, bool bundling = false);
  bool finished() const {
    return next_ >= steps_.size() && waiting_ == 0 && !waiting_loaded_ && !waiting_exported_ && !waiting_bundled_;
  }
  bool empty() const { return steps_.empty(); }

 private:
  std::vector<ScriptStep> steps_;
  size_t next_ = 0;
  uint32_t waiting_ = 0;
  bool waiting_loaded_ = false;
  bool waiting_exported_ = false;
  bool waiting_bundled_ = false;
};

}  // namespace fibscope
