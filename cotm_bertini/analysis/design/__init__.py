"""Design: free lengths that hold a pose, the paper's fold curves, count changes on maps."""
