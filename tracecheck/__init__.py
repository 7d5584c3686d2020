"""Trace validation (issue 11): a run's bus trace held against the verified protocol models.

Sits above model_check and the generated package (it imports both); sim2d
imports it to report `protocol.violations`, and `arachnae trace check` runs it
on a saved trace alone, so a capture from real hardware is checked the same way.
"""
