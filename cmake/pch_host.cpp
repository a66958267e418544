// Empty: the translation unit that builds a precompiled header (cmake/whirl_targets.cmake).
