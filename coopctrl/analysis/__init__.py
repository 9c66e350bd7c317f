"""Numerical analysis of a scenario's closed loop: stability limits of the integrators, the
speed-accuracy trade against a reference solution, and the model-fidelity trade.

One concept per module; import them directly (``from coopctrl.analysis.stability import ...``):
this package does not import its modules eagerly, so that the CLI starts fast.
"""
