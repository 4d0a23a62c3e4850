"""Solver backends: render, run and parse, each producing one typed endpoint table."""
