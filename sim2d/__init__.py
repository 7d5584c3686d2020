"""sim2d: a 2-D simulation of ARACHNAE II, its world and its bus network (issue 4).

Layers, each its own module: scenario (YAML in), world (pymunk geometry and
fields), robot (legs, joints, body kinematics), sensors (physics to raw
values), bus (discrete-event RS-485), sim (the event loop), metrics/expect,
render, cli.
"""
