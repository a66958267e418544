# Sources of src/sim (owned by the sim module). Add files with target_sources(whirl_core PRIVATE ...).
