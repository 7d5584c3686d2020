"""sim2d: a 2-D simulation of ARACHNAE II, its world and its bus network (issue 4).

Layers, each its own module: scenario (YAML in), world (pymunk geometry and
fields), robot (legs, joints, body kinematics), sensors (physics in physical
units), bus (discrete-event RS-485), hardware (a node's board), sim (the
event loop), metrics/expect, render, cli. The nodes themselves are the
top-level package `behaviours` on the generated skeletons (arachnae_proto).
"""
