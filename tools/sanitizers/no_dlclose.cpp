// Linked into every target of the sanitized build only (PLUME_SANITIZE, tools/test --sanitize):
// dlclose does nothing, so the Vulkan driver (lavapipe) and the validation layer that the loader
// opened stay mapped until the process exits. LeakSanitizer looks for leaks at exit, after the
// loader has unloaded them: memory that a library still points to from its own globals (lavapipe
// builds some tables once and never frees them) then looks leaked, and the frames of the unmapped
// library print as "<unknown module>", which no suppression can match. Newer Vulkan loaders do
// the same with VK_LOADER_DISABLE_DYNAMIC_LIBRARY_UNLOADING=1; Debian 12's (1.3.239) predates it.
extern "C" __attribute__((visibility("default"))) int dlclose(void*) { return 0; }
