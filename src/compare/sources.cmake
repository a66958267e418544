# Sources of src/compare (owned by the compare module). Add files with target_sources(whirl_core PRIVATE ...).
