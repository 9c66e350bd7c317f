"""Column layout of the packed parameter arrays handed to the compiled core.

The kernels take plain float64/int64 arrays (no Python objects). Each row is the same doubles, in the same
order, as a struct of the compiled core (``plants/core/elastic_model.h``), and its columns are named here, in
one place (:class:`RowLayout`): the packers write them by name (``SPATIAL_SPRING["stiffness"]``), the compiled
core reads them through the struct's fields.

Edge rows (one per interconnection, docs/model.md s.3), ``EDGE_WIDTH_SPATIAL`` or ``EDGE_WIDTH_PLANAR``
columns; which struct reads a row is its header's element kind:

``SPATIAL_SPRING`` (``SpatialSpring``, central and offset elements)
    ``stiffness`` c per axis [N/m]; ``torsion`` cA per Euler axis [N m/rad]; ``rest_length`` l [m];
    ``rest_angles`` A0 [rad]; ``rest_offset`` rho of node j in node i's frame [m] (offset element);
    ``damping`` d along the line [N s/m]; ``torsion_damping`` dA [N m s/rad]; ``kappa`` rotation-invariant
    orientation weights [N m] (offset element); ``rest_rotation`` R0 = ``R_i^T R_j`` at rest, row-major
    (offset element; also the geodesic rotation form's rest value); ``rotation_form`` (``ROTATION_BOOK`` =
    0.0, ``ROTATION_GEODESIC`` = 1.0).
``PLANAR_SPRING`` (``PlanarSpring``)
    ``stiffness`` (2), ``torsion``, ``rest_length``, ``rest_angle``, ``rest_offset`` (2), ``damping``,
    ``torsion_damping``.
``SPATIAL_MATRIX`` / ``PLANAR_MATRIX`` (``SpatialMatrixElement`` / ``PlanarMatrixElement``, matrix and beam
elements, co-rotational with node i clamped in the element frame)
    ``stiffness_jj`` K_jj and ``damping_jj`` C_jj (row-major), ``rest_offset`` u0 of node j in the element
    frame [m]; spatial ``frame_in_i`` M = R_i0^T R_e0 and ``frame_in_j`` N = R_j0^T R_e0 (row-major); planar
    ``frame_angle`` alpha = theta_e0 - theta_i0 and ``rest_angle`` beta = theta_j0 - theta_i0 [rad]; the
    immobile model's ``stiffness_linear`` K_lin = G0^T K_jj G0 and ``damping_linear`` D_lin (2p x 2p).

Edge index rows (the element header ``ElasticEdge``): ``(i, j, element, damping form)`` with element
``ELEMENT_CENTRAL``, ``ELEMENT_OFFSET`` or ``ELEMENT_MATRIX`` and damping form ``DAMPING_FRAME_INVARIANT`` or
``DAMPING_BOOK``. Node rows: spatial ``(mass, I1, I2, I3)``; planar ``(mass, I)`` [kg, kg m^2]. A spatial plant
whose nodes' angles are taken in charts (docs/model.md s.2, rotation charts) packs wider rows,
``CHARTED_NODE`` (``ChartedSpatialNode``, ``NODE_WIDTH_CHARTED`` columns): ``chart_kind`` (``CHART_WORLD``,
``CHART_STORED``, ``CHART_OWN``) and the stored chart ``chart`` row-major. The kernels read the chart columns
only when the rows are that wide, so a plant in the book's world chart keeps 4 columns.
"""


class RowLayout:
    """The named columns of one packed row: its fields in order, each ``(first column, columns)``.

    ``layout["field"]`` is the field's slice of a row, ``layout.col("field")`` its first column and
    ``layout.width`` the columns of the whole struct. The compiled core's struct of the same name has the same
    fields at the same offsets (``plants._core.elastic_layout()``; tests/test_core_elastic.py checks it)."""

    def __init__(self, struct: str, *fields: tuple[str, int]):
        self.struct = struct
        self.fields: dict[str, tuple[int, int]] = {}
        col = 0
        for name, size in fields:
            self.fields[name] = (col, size)
            col += size
        self.width = col

    def col(self, field: str) -> int:
        """The first column of ``field``."""
        return self.fields[field][0]

    def __getitem__(self, field: str) -> slice:
        first, size = self.fields[field]
        return slice(first, first + size)


EDGE_HEADER = RowLayout("ElasticEdge", ("i", 1), ("j", 1), ("kind", 1), ("damping_form", 1))  # int64 columns
SPATIAL_SPRING = RowLayout("SpatialSpring", ("stiffness", 3), ("torsion", 3), ("rest_length", 1),
                           ("rest_angles", 3), ("rest_offset", 3), ("damping", 1), ("torsion_damping", 1),
                           ("kappa", 3), ("rest_rotation", 9), ("rotation_form", 1))
SPATIAL_MATRIX = RowLayout("SpatialMatrixElement", ("stiffness_jj", 36), ("damping_jj", 36), ("rest_offset", 3),
                           ("frame_in_i", 9), ("frame_in_j", 9), ("stiffness_linear", 144),
                           ("damping_linear", 144))
PLANAR_SPRING = RowLayout("PlanarSpring", ("stiffness", 2), ("torsion", 1), ("rest_length", 1), ("rest_angle", 1),
                          ("rest_offset", 2), ("damping", 1), ("torsion_damping", 1))
PLANAR_MATRIX = RowLayout("PlanarMatrixElement", ("stiffness_jj", 9), ("damping_jj", 9), ("rest_offset", 2),
                          ("frame_angle", 1), ("rest_angle", 1), ("stiffness_linear", 36), ("damping_linear", 36))
SPATIAL_NODE = RowLayout("SpatialNode", ("mass", 1), ("inertia", 3))
PLANAR_NODE = RowLayout("PlanarNode", ("mass", 1), ("inertia", 1))
CHARTED_NODE = RowLayout("ChartedSpatialNode", ("mass", 1), ("inertia", 3), ("chart_kind", 1), ("chart", 9))

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

#: Columns of a node row: the mass and the first principal moment of inertia (the same columns in
#: ``SPATIAL_NODE`` and ``PLANAR_NODE``, so the planar kernels read them too).
NODE_MASS = SPATIAL_NODE.col("mass")
NODE_INERTIA = SPATIAL_NODE.col("inertia")

#: Node rows with charts: the chart kind column and the first column of the stored chart.
NODE_CHART_KIND = CHARTED_NODE.col("chart_kind")
NODE_CHART = CHARTED_NODE.col("chart")
NODE_WIDTH_CHARTED = CHARTED_NODE.width
#: Chart kinds: the book's world chart (``R = R(A)``), a stored constant chart (``R = C R(A)``,
#: ``C`` in the node row), a node's own chart for this evaluation (an arm's node: ``C = R_tip(q)``,
#: ``A = 0``; the arm kernel writes ``C`` into the node's frames block ``FRAME_CHART``).
CHART_WORLD = 0
CHART_STORED = 1
CHART_OWN = 2

#: Columns of an edge row: the widest element of each space (a matrix element's row).
EDGE_WIDTH_SPATIAL = SPATIAL_MATRIX.width
EDGE_WIDTH_PLANAR = PLANAR_MATRIX.width

# kernel status codes
STATUS_OK = 0
STATUS_EULER_SINGULAR = 1
STATUS_COINCIDENT_NODES = 2
STATUS_SINGULAR_MASS = 3
