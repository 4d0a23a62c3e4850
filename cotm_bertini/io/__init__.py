"""Results on disk: the solve cache, run folders, column references."""
