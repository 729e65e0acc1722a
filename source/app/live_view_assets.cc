// SPDX-License-Identifier: LGPL-2.1-or-later
// Copyright (C) 2026 the palpate authors

// The live view's 3-D rendering, compiled in: three.js's two ES modules
// (three.module.js imports three.core.js) and its OrbitControls (the
// camera's orbit, pan and zoom; it imports 'three', which the page's
// import map names /three.module.js), installed from npm by cmake
// (source/app/web/package-lock.json pins the version and its checksum) and
// embedded here with the assembler's .incbin, so that palpate serve needs
// no file of it at run time. Without npm at cmake time all are empty and
// palpate serve says what to install.

#include <cstddef>
#include <string_view>

#ifdef PALPATE_THREE_DIR
// Each file between two hidden labels, with a NUL after it (not counted).
asm(".section .rodata\n"
    ".balign 16\n"
    ".global palpate_three_core_begin\n"
    ".hidden palpate_three_core_begin\n"
    "palpate_three_core_begin:\n"
    ".incbin \"" PALPATE_THREE_DIR "/three.core.js\"\n"
    ".global palpate_three_core_end\n"
    ".hidden palpate_three_core_end\n"
    "palpate_three_core_end:\n"
    ".byte 0\n"
    ".balign 16\n"
    ".global palpate_three_module_begin\n"
    ".hidden palpate_three_module_begin\n"
    "palpate_three_module_begin:\n"
    ".incbin \"" PALPATE_THREE_DIR "/three.module.js\"\n"
    ".global palpate_three_module_end\n"
    ".hidden palpate_three_module_end\n"
    "palpate_three_module_end:\n"
    ".byte 0\n"
    ".balign 16\n"
    ".global palpate_three_orbit_begin\n"
    ".hidden palpate_three_orbit_begin\n"
    "palpate_three_orbit_begin:\n"
    ".incbin \"" PALPATE_THREE_DIR
    "/../examples/jsm/controls/OrbitControls.js\"\n"
    ".global palpate_three_orbit_end\n"
    ".hidden palpate_three_orbit_end\n"
    "palpate_three_orbit_end:\n"
    ".byte 0\n"
    ".previous\n");

extern "C"
{
  extern const char palpate_three_core_begin[], palpate_three_core_end[];
  extern const char palpate_three_module_begin[], palpate_three_module_end[];
  extern const char palpate_three_orbit_begin[], palpate_three_orbit_end[];
}
#endif

namespace palpate
{
  namespace live_view_assets
  {
#ifdef PALPATE_THREE_DIR
    namespace
    {
      std::string_view
      between(const char *begin, const char *end)
      {
        return {begin, static_cast<std::size_t>(end - begin)};
      }
    } // namespace
#endif

    std::string_view
    three_core();
    std::string_view
    three_module();
    std::string_view
    orbit_controls();

    /** three.js's core module (three.core.js); empty if not built in. */
    std::string_view
    three_core()
    {
#ifdef PALPATE_THREE_DIR
      return between(palpate_three_core_begin, palpate_three_core_end);
#else
      return {};
#endif
    }

    /** three.js's module (three.module.js, which imports three.core.js);
     * empty if not built in. */
    std::string_view
    three_module()
    {
#ifdef PALPATE_THREE_DIR
      return between(palpate_three_module_begin, palpate_three_module_end);
#else
      return {};
#endif
    }

    /** three.js's OrbitControls (examples/jsm/controls/OrbitControls.js,
     * which imports 'three'); empty if not built in. */
    std::string_view
    orbit_controls()
    {
#ifdef PALPATE_THREE_DIR
      return between(palpate_three_orbit_begin, palpate_three_orbit_end);
#else
      return {};
#endif
    }
  } // namespace live_view_assets
} // namespace palpate
