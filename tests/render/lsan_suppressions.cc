// LeakSanitizer suppressions for the renderer's test binaries, read in sanitizer builds
// (-DKINOGRAPH_SANITIZE=ON); harmless otherwise. Third-party leaks at exit only: fontconfig
// (loaded by cairo for label and plot text) keeps its configuration and font patterns, OSMesa
// keeps per-context state after OSMesaDestroyContext. The same list is in lsan.supp for the
// kinograph binary the CLI test runs.
extern "C" const char* __lsan_default_suppressions() {
  return "leak:libfontconfig.so\nleak:libOSMesa.so\n";
}
