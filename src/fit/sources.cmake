# Sources of src/fit (owned by the fit module). Add files with target_sources(whirl_core PRIVATE ...).
