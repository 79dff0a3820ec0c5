// Keeps the Vulkan driver and layers mapped until the process exits, in
// builds with AddressSanitizer (whose LeakSanitizer checks at exit).
//
// Why: the loader unloads the driver (Mesa's lavapipe, with LLVM) and the
// layers when the instance is destroyed. What such a library allocated once
// per process and keeps in its own globals (llvmpipe's one-time
// initialisation under vkEnumeratePhysicalDevices, 128-256 bytes in Mesa
// 22.3) then looks leaked at exit, because the globals that pointed to it
// went with the library, and LeakSanitizer names its frames "<unknown
// module>", which no suppression can match. Kept mapped, those globals are
// scanned again (so nothing is reported), and what a library really leaks
// is reported under its own module's name, which tests/lsan_suppressions.txt
// can name (it names the validation layer, and only third-party libraries).
// fibscope's own allocations are leak-checked exactly as before.
#pragma once

namespace fibscope::gpu {

// True in builds with AddressSanitizer: pinLibrariesForLeakChecks() pins.
bool leakChecksPinLibraries();

// Marks every shared library loaded now as never to be unloaded
// (RTLD_NODELETE); later dlclose calls leave it mapped. Safe to call again.
void pinLoadedLibraries();

// pinLoadedLibraries() in builds with AddressSanitizer; nothing otherwise
// (a release build unloads the driver as the loader intends). Called before
// every vkDestroyInstance.
void pinLibrariesForLeakChecks();

}  // namespace fibscope::gpu
