# Sources of src/nn (owned by the nn module). Add files with target_sources(whirl_core PRIVATE ...).
