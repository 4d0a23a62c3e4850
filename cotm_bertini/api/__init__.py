"""The public API: solve a parameter set, sweep parameters; results as objects."""
