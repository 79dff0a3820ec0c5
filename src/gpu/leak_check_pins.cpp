#include "gpu/leak_check_pins.h"

#include <dlfcn.h>
#include <link.h>

// gcc defines __SANITIZE_ADDRESS__; clang (the fuzzers) answers __has_feature.
#if defined(__SANITIZE_ADDRESS__)
#define FIBSCOPE_HAS_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define FIBSCOPE_HAS_ASAN 1
#endif
#endif

namespace fibscope::gpu {

bool leakChecksPinLibraries() {
#ifdef FIBSCOPE_HAS_ASAN
  return true;
#else
  return false;
#endif
}

void pinLoadedLibraries() {
  dl_iterate_phdr(
      [](dl_phdr_info* info, size_t, void*) {
        // RTLD_NOLOAD: only takes a reference to what is loaded already
        // (the main program has an empty name and is never unloaded).
        if (info->dlpi_name && info->dlpi_name[0] != '\0')
          dlopen(info->dlpi_name, RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
        return 0;
      },
      nullptr);
}

void pinLibrariesForLeakChecks() {
  if (leakChecksPinLibraries()) pinLoadedLibraries();
}

}  // namespace fibscope::gpu
