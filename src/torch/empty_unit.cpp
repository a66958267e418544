// Temporary empty unit so the target configures; the torch owner replaces it.
