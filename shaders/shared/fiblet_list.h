// A list of fiblets to draw, written by a cull pass and read by the fiblet
// raster: an indirect-dispatch command first (so the buffer can be passed
// to vkCmdDispatchIndirect at offset 0), then the count, then the indices.
//
// The cull pass appends with atomicAdd on `count`; a one-invocation pass
// then turns the count into a 2D grid no wider than the device allows
// (dispatch_x * dispatch_y >= count; the raster skips flat indices >=
// count).
#ifndef FIBSCOPE_SHADERS_SHARED_FIBLET_LIST_H
#define FIBSCOPE_SHADERS_SHARED_FIBLET_LIST_H

#include "shared/glsl_cpp.h"

SHADER_NAMESPACE_BEGIN

struct FibletListHeader {
  uint dispatch_x;  // VkDispatchIndirectCommand
  uint dispatch_y;
  uint dispatch_z;
  uint count;       // fiblets in the list
};
// The fiblet indices (uint each) follow the header.

SHADER_NAMESPACE_END

#ifdef __cplusplus
static_assert(sizeof(fibscope::shader::FibletListHeader) == 16, "indirect command + count");
#endif

#endif  // FIBSCOPE_SHADERS_SHARED_FIBLET_LIST_H
