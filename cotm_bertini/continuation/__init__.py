"""Continuation: sweeps over parameters, branches across sweep points, events between them."""
