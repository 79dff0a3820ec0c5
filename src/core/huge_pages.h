// Transparent huge pages for large buffers filled once.
#pragma once

#include <cstddef>

namespace fibscope {

// Asks the kernel to back the whole 2 MiB pages inside [data, data + bytes)
// of an anonymous allocation with transparent huge pages (madvise
// MADV_HUGEPAGE): for large buffers filled once, one page fault per 2 MiB
// instead of per 4 KiB. Best effort: does nothing where unsupported.
void adviseHugePages(void* data, size_t bytes);

}  // namespace fibscope
