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
    ``R0[18:27]`` rest relative rotation ``R_i^T R_j`` row-major (offset element; also the
    geodesic rotation form's rest value); ``form[27]`` the rotation form
    (``ROTATION_BOOK`` = 0.0, ``ROTATION_GEODESIC`` = 1.0; central and offset elements).
planar (``EDGE_WIDTH_PLANAR`` columns)
    ``c[0:2]``, ``cA[2]``, ``l[3]``, ``A0[4]``, ``rho[5:7]``, ``d[7]``, ``dA[8]``.

Matrix element rows (``ELEMENT_MATRIX``, both spaces): see the ``MATRIX_*`` columns below.

Edge index rows: ``(i, j, element, damping form)`` with element ``ELEMENT_CENTRAL``,
``ELEMENT_OFFSET`` or ``ELEMENT_MATRIX`` and damping form ``DAMPING_FRAME_INVARIANT`` or ``DAMPING_BOOK``.
Node rows: spatial ``(mass, I1, I2, I3)``; planar ``(mass, I)`` [kg, kg m^2]. A spatial plant
whose nodes' angles are taken in charts (docs/model.md s.2, rotation charts) packs wider rows,
``NODE_WIDTH_CHARTED`` columns: ``chart kind[4]`` (``CHART_WORLD``, ``CHART_STORED``,
``CHART_OWN``) and the stored chart ``C[5:14]`` row-major. The kernels read the chart columns
only when the rows are that wide, so a plant in the book's world chart keeps 4 columns.
"""

ELEMENT_CENTRAL = 0
ELEMENT_OFFSET = 1
ELEMENT_MATRIX = 2
ELEMENTS = {"central": ELEMENT_CENTRAL, "offset": ELEMENT_OFFSET, "matrix": ELEMENT_MATRIX,
            "beam": ELEMENT_MATRIX}  # a beam is packed as its element matrix

DAMPING_FRAME_INVARIANT = 0
DAMPING_BOOK = 1
DAMPING_FORMS = {"frame_invariant": DAMPING_FRAME_INVARIANT, "book": DAMPING_BOOK}

ROTATION_BOOK = 0
ROTATION_GEODESIC = 1
ROTATION_FORMS = {"book": ROTATION_BOOK, "geodesic": ROTATION_GEODESIC}
#: Column of the rotation form in a spatial central or offset edge row (0.0 book, 1.0 geodesic).
ROTATION_FORM_COL = 27

#: Node rows with charts: the chart kind column and the first column of the stored chart.
NODE_CHART_KIND = 4
NODE_CHART = 5
NODE_WIDTH_CHARTED = 14
#: Chart kinds: the book's world chart (``R = R(A)``), a stored constant chart (``R = C R(A)``,
#: ``C`` in the node row), a node's own chart for this evaluation (an arm's node: ``C = R_tip(q)``,
#: ``A = 0``; the arm kernel writes ``C`` into the node's frames block ``FRAME_CHART``).
CHART_WORLD = 0
CHART_STORED = 1
CHART_OWN = 2

EDGE_WIDTH_SPATIAL = 381
EDGE_WIDTH_PLANAR = 94

# matrix element (co-rotational, node i clamped in the element frame; docs/model.md s.3)
MATRIX_K = 0          # spatial: K_jj 6x6 row-major [0:36]; planar: 3x3 [0:9]
MATRIX_C_SPATIAL = 36  # damping C_jj 6x6 [36:72]
MATRIX_U0_SPATIAL = 72  # rest position of node j in the element frame [72:75]
MATRIX_M_SPATIAL = 75  # M = R_i0^T R_e0 row-major [75:84]: the element frame in node i's frame
MATRIX_N_SPATIAL = 84  # N = R_j0^T R_e0 row-major [84:93]: the element frame in node j's rest frame
MATRIX_LINEAR_SPATIAL = 93  # immobile model: K_lin = G0^T K_jj G0 (12x12) [93:237] and D_lin = G0^T C_jj G0 [237:381]
MATRIX_C_PLANAR = 9     # C_jj 3x3 [9:18]
MATRIX_U0_PLANAR = 18   # [18:20]
MATRIX_ALPHA_PLANAR = 20  # element angle in node i's frame, theta_e0 - theta_i0 [rad]
MATRIX_BETA_PLANAR = 21   # rest relative angle theta_j0 - theta_i0 [rad]
MATRIX_LINEAR_PLANAR = 22  # K_lin (6x6) [22:58] and D_lin [58:94]

# kernel status codes
STATUS_OK = 0
STATUS_EULER_SINGULAR = 1
STATUS_COINCIDENT_NODES = 2
STATUS_SINGULAR_MASS = 3
