// Temporary empty unit so the target configures; the interp owner replaces sources.cmake.
