"""The per-state quantities a model-based controller reads from the plant."""

from __future__ import annotations


class ControlTerms:
    """Everything a model-based controller needs at one state, from one pass over the kernels.

    Attributes (N = m + 1 nodes, p pose size, n max joints per arm):
        Y, dY: (N, p) node poses and rates.
        H, h: (m, n, n) arm inertias and (m, n) bias torques [N m].
        J, Jdq: (m, p, n) analytic Jacobians and (m, p) ``dJ/dt dq``.
        W: (N, p, p) node inertia blocks ``W_i``.
        w_free: (N, p) node terms of ``w`` without the interconnections: gyroscopic - gravity.
        S: (N, p) interconnection terms of ``w``: ``dPi/dY_i + dD/d(dY_i)``.
        Fw: (m, p) wrench each contact applies to the object (see ``contact_wrenches``).
        z, dz: the generalized coordinates ``z = (q, Y_0)`` and rates of the state, or ``None``
            (the joint positions a null-space posture task reads).
    """

    __slots__ = ("Y", "dY", "H", "h", "J", "Jdq", "W", "w_free", "S", "Fw", "z", "dz")

    def __init__(self, Y, dY, H, h, J, Jdq, W, w_free, S, Fw, z=None, dz=None):
        self.Y, self.dY, self.H, self.h, self.J, self.Jdq = Y, dY, H, h, J, Jdq
        self.W, self.w_free, self.S, self.Fw = W, w_free, S, Fw
        self.z, self.dz = z, dz
