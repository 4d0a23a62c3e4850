"""Quasi-static motion: a stable state followed along a path of the actuators (free lengths,
anchors, loads), its snaps at folds and cable switches, and plans between stable states."""
