"""Explicit-state model checker for the ARACHNAE II protocols (issue 3).

Models are guarded-command programs (`gcl.Model`) built from the spec; the same
program is compiled to fast Python (`compile`) for our breadth-first checker
(`engine`) and emitted as Promela (`promela`) so SPIN can cross-check it.
"""
