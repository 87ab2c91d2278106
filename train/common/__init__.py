"""Plumbing shared by the tools: one-line failures, atomic writes, command-line values
and the seed ranges."""
