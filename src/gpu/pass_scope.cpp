#include "gpu/pass_scope.h"

#include "gpu/submit.h"

namespace fibscope::gpu {

void recordBarrier(VkCommandBuffer cmd, const PassBarrier& b) {
  if (b.src_stage == 0 && b.dst_stage == 0) return;
  memoryBarrier(cmd, b.src_stage, b.src_access, b.dst_stage, b.dst_access);
}

PassScope::PassScope(VkCommandBuffer cmd, GpuTimer* timer, const std::string& name, const PassBarrier& after)
    : cmd_(cmd), timer_(timer), after_(after) {
  if (timer_) beginPass(cmd_, *timer_, name);
}

PassScope::~PassScope() {
  if (timer_) endPass(cmd_, *timer_);
  recordBarrier(cmd_, after_);
}

}  // namespace fibscope::gpu
