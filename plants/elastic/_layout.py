"""Column layout of the packed parameter arrays handed to the numba kernels.

The kernels take plain float64/int64 arrays (no Python objects), so the meaning of each column
is fixed here, in one place, and used by both the packers and the kernels.

Edge rows (one per interconnection, docs/model.md s.3):

spatial (``EDGE_WIDTH_SPATIAL`` columns)
    ``c[0:3]`` translational stiffness per axis [N/m]; ``cA[3:6]`` torsion stiffness per
    Euler axis [N m/rad]; ``l[6]`` rest length [m]; ``A0[7:10]`` rest Euler difference [rad];
    ``rho[10:13]`` rest offset of node j in node i's frame [m] (offset element);
    ``d[13]`` damping along the line [N s/m]; ``dA[14]`` torsion damping [N m s/rad];
    ``kappa[15:18]`` rotation-invariant orientation weights [N m] (offset element);
    ``R0[18:27]`` rest relative rotation ``R_i^T R_j`` row-major (offset element).
planar (``EDGE_WIDTH_PLANAR`` columns)
    ``c[0:2]``, ``cA[2]``, ``l[3]``, ``A0[4]``, ``rho[5:7]``, ``d[7]``, ``dA[8]``.

Edge index rows: ``(i, j, element, damping form)`` with element ``ELEMENT_CENTRAL`` or
``ELEMENT_OFFSET`` and damping form ``DAMPING_FRAME_INVARIANT`` or ``DAMPING_BOOK``.
Node rows: spatial ``(mass, I1, I2, I3)``; planar ``(mass, I)`` [kg, kg m^2].
"""

ELEMENT_CENTRAL = 0
ELEMENT_OFFSET = 1
ELEMENTS = {"central": ELEMENT_CENTRAL, "offset": ELEMENT_OFFSET}

DAMPING_FRAME_INVARIANT = 0
DAMPING_BOOK = 1
DAMPING_FORMS = {"frame_invariant": DAMPING_FRAME_INVARIANT, "book": DAMPING_BOOK}

EDGE_WIDTH_SPATIAL = 27
EDGE_WIDTH_PLANAR = 9

# kernel status codes
STATUS_OK = 0
STATUS_EULER_SINGULAR = 1
STATUS_COINCIDENT_NODES = 2
STATUS_SINGULAR_MASS = 3
