"""``[[springs]]``: one elastic interconnection between two nodes (docs/model.md §3, (106-111))."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import boolean, choice, integer, number, optional_number, scalar_or_vector, vector
from coopctrl.scenario.schema import key, limits

ELEMENTS = ("central", "offset", "matrix", "beam")
DAMPING_FORMS = ("frame_invariant", "book")
ROTATION_FORMS = ("book", "geodesic")


@dataclass(frozen=True)
class SpringConfig:
    """One interconnection between nodes ``pair = [i, j]`` (0 = object, k = arm k's node).

    Attributes:
        pair: The two node indices, distinct, each in 0..m.
        stiffness: Translational stiffness ``c_ij`` in [N/m], > 0: a scalar or one value per
            translational axis (2 planar: x, z; 3 spatial: x, y, z).
        torsion: Torsional stiffness ``cA_ij`` in [N m/rad], >= 0: a scalar or one value per
            rotational axis (1 planar; 3 spatial: psi, theta, phi). 0 drops the torsion springs.
        damping: Damping along the line ``d_ij`` in [N s/m], >= 0 (110-111).
        torsion_damping: Rotational damping ``dA_ij`` in [N m s/rad], >= 0.
        element: ``"central"`` (the book's spring with rest length plus Euler-difference torsion
            springs; no lateral stiffness without pre-tension), ``"offset"`` (rest offset fixed in
            the object frame, so it also has shear stiffness; docs/model.md §3, known limit),
            ``"matrix"`` (a finite element given by its stiffness matrix, key ``matrix``) or
            ``"beam"`` (an Euler-Bernoulli or Timoshenko beam between the nodes, keys ``E`` to
            ``internal_nodes``): both co-rotational, exact under large rigid motions
            (docs/model.md §3, (47)-(59)).
        damping_form: ``"frame_invariant"`` (default: the dampers act on the rate of the deformation,
            the elongation in the element's frame and the relative angular velocity, so they do no
            work under a rigid motion; docs/model.md §3 [ours]) or ``"book"`` (110-111: world velocity
            differences and Euler-rate differences, as in the book).
        rotation_form: The rotational spring of a spatial ``"central"`` or ``"offset"`` element:
            ``"geodesic"`` (``1/2 e^T C_A e`` on the relative rotation vector ``e = log(R_i^T R_j R0^T)``:
            chart-free; docs/model.md s.3) or ``"book"`` (the central element's torsion springs on the
            Euler difference ``A_i - A_j - A0``, the offset element's ``kappa`` form). Absent:
            ``"geodesic"`` when the scene's rotations are in charts, else ``"book"``. Not read for matrix
            and beam elements, nor in a planar scene (one angle: both forms are the same).
        matrix: ``element = "matrix"``: the element's stiffness in its own frame, 12x12 (spatial:
            ``(u, v, w, rx, ry, rz)`` of node i then node j) or 6x6 (planar: ``(u, w, theta)``),
            [N/m, N, N m/rad]: symmetric, positive semi-definite, leaving the element's rigid
            motions free (docs/model.md §3, (47)). ``stiffness``, ``torsion``, ``damping`` and
            ``torsion_damping`` do not apply to matrix and beam elements.
        matrix_damping: ``element = "matrix"``: its damping matrix, same shape and conditions
            [N s/m, N s, N m s/rad]; default ``rayleigh_damping`` times ``matrix``.
        frame: ``element = "matrix"``: the element frame's ZYX Euler angles [rad] in the world (3
            spatial, 1 planar); default: x along the line from node i to node j at rest, y
            horizontal.
    """

    pair: tuple[int, int]
    stiffness: float | tuple[float, ...] = key(
        1.0e4, unit="N/m", gt=0, le=1e10,
        why="a steel-on-steel contact is about 1e9 N/m; beyond 1e10 N/m a grasp is rigid for any step "
        "the simulation can take (1.8e308 hung the pseudo-inverse of the grasp compliance)")
    torsion: float | tuple[float, ...] = key(
        10.0, unit="N m/rad", ge=0, le=1e9, why="1e9 N m/rad is stiffer than any gripper's wrist joint by decades")
    damping: float = key(20.0, unit="N s/m", ge=0, le=1e7,
                         why="1e7 N s/m damps a 1e10 N/m spring on a 1 kg node far beyond critical")
    torsion_damping: float = key(0.05, unit="N m s/rad", ge=0, le=1e6, why="as damping, for rotations")
    element: str = key("offset", allowed=ELEMENTS)
    damping_form: str = key("frame_invariant", allowed=DAMPING_FORMS)
    rotation_form: str | None = key(None, allowed=ROTATION_FORMS)
    matrix: tuple[tuple[float, ...], ...] | None = None
    matrix_damping: tuple[tuple[float, ...], ...] | None = None
    frame: tuple[float, ...] | None = None
    E: float | None = key(None, unit="Pa", gt=0, le=1.2e12,
                          why="element = 'beam': Young's modulus; diamond's 1.2e12 Pa is the stiffest solid")
    G: float | None = key(None, unit="Pa", gt=0, le=1.2e12, why="element = 'beam': shear modulus, as E")
    A: float | None = key(None, unit="m^2", gt=0, le=1.0, why="element = 'beam': cross-section area; 1 m^2 is no carried object")
    Iy: float | None = key(None, unit="m^4", gt=0, le=1.0,
                           why="element = 'beam': second moment about the beam's y axis (horizontal, normal to "
                           "it); 1 m^4 is no carried object")
    Iz: float | None = key(None, unit="m^4", gt=0, le=1.0, why="element = 'beam': second moment about its z axis (spatial)")
    J: float | None = key(None, unit="m^4", gt=0, le=1.0, why="element = 'beam': torsion constant (spatial)")
    shear: bool = key(False, why="element = 'beam': Timoshenko shear deformation (shear coefficient 5/6)")
    internal_nodes: int = key(0, ge=0, le=64, why="element = 'beam': massless nodes equally spaced along it, condensed "
                              "by (53)-(54); 64 resolves any bending shape a lumped node mass can show")
    rayleigh_damping: float = key(0.0, unit="s", ge=0, le=1.0,
                                  why="matrix and beam elements: damping matrix beta K (stiffness proportional); "
                                  "beta = 1 s damps every mode above 2 rad/s beyond critical")

    def __post_init__(self) -> None:
        s = object.__setattr__
        pair = self.pair
        allowed = "two distinct node indices [i, j] >= 0 (0 = object, k = arm k)"
        if (
            not isinstance(pair, (list, tuple))
            or len(pair) != 2
            or any(isinstance(p, bool) or not isinstance(p, int) or p < 0 for p in pair)
            or pair[0] == pair[1]
        ):
            raise ScenarioError("pair", pair, allowed)
        s(self, "pair", (int(pair[0]), int(pair[1])))
        s(self, "stiffness", scalar_or_vector("stiffness", self.stiffness, **limits(self, "stiffness")))
        s(self, "torsion", scalar_or_vector("torsion", self.torsion, **limits(self, "torsion")))
        s(self, "damping", number("damping", self.damping, **limits(self, "damping")))
        s(self, "torsion_damping", number("torsion_damping", self.torsion_damping, **limits(self, "torsion_damping")))
        s(self, "element", choice("element", self.element, ELEMENTS))
        s(self, "damping_form", choice("damping_form", self.damping_form, DAMPING_FORMS))
        if self.rotation_form is not None:  # None: the scene's (Scenario)
            s(self, "rotation_form", choice("rotation_form", self.rotation_form, ROTATION_FORMS))
        s(self, "rayleigh_damping", number("rayleigh_damping", self.rayleigh_damping, **limits(self, "rayleigh_damping")))
        s(self, "shear", boolean("shear", self.shear))
        s(self, "internal_nodes", integer("internal_nodes", self.internal_nodes, minimum=0, maximum=64))
        beam = ("E", "G", "A", "Iy", "Iz", "J")
        for name in beam:
            s(self, name, optional_number(name, getattr(self, name), **limits(self, name)))
        if self.element == "beam":
            for name in ("E", "G", "A", "Iy"):
                if getattr(self, name) is None:
                    raise ScenarioError(name, None, f"a number for element = 'beam' ({_UNITS[name]}; Iz and J too in a "
                                        "spatial scene)")
        elif any(getattr(self, name) is not None for name in beam) or self.shear or self.internal_nodes:
            raise ScenarioError("element", self.element, "'beam' when E, G, A, Iy, Iz, J, shear or internal_nodes are given")
        if self.element == "matrix":
            if self.matrix is None:
                raise ScenarioError("matrix", None, "a 12x12 (spatial) or 6x6 (planar) stiffness for element = 'matrix'")
            s(self, "matrix", _matrix("matrix", self.matrix))
            if self.matrix_damping is not None:
                s(self, "matrix_damping", _matrix("matrix_damping", self.matrix_damping))
                if len(self.matrix_damping) != len(self.matrix):
                    raise ScenarioError("matrix_damping", f"{len(self.matrix_damping)} rows",
                                        f"the shape of matrix ({len(self.matrix)}x{len(self.matrix)})")
            if self.frame is not None:
                s(self, "frame", vector("frame", self.frame, lengths=(1, 3), what="ZYX Euler angles [rad] (3 spatial, 1 planar)"))
        else:
            for name in ("matrix", "matrix_damping", "frame"):
                if getattr(self, name) is not None:
                    raise ScenarioError("element", self.element, f"'matrix' when {name} is given")

    def stiffness_per_axis(self, space: str) -> tuple[float, ...]:
        """Translational stiffness per axis [N/m] (2 planar, 3 spatial)."""
        n = 2 if space == "planar" else 3
        return self.stiffness if isinstance(self.stiffness, tuple) else (self.stiffness,) * n

    def torsion_per_axis(self, space: str) -> tuple[float, ...]:
        """Torsional stiffness per axis [N m/rad] (1 planar, 3 spatial)."""
        n = 1 if space == "planar" else 3
        return self.torsion if isinstance(self.torsion, tuple) else (self.torsion,) * n


_UNITS = {"E": "Pa", "G": "Pa", "A": "m^2", "Iy": "m^4", "Iz": "m^4", "J": "m^4"}


def _matrix(path: str, value) -> tuple[tuple[float, ...], ...]:
    """A square 12x12 or 6x6 table of finite numbers, symmetric and positive semi-definite."""
    what = "a symmetric positive semi-definite 12x12 (spatial) or 6x6 (planar) matrix, a list of rows [SI]"
    if not isinstance(value, (list, tuple)) or len(value) not in (6, 12):
        raise ScenarioError(path, f"{len(value)} rows" if isinstance(value, (list, tuple)) else value, what)
    n = len(value)
    rows = tuple(vector(f"{path}[{i}]", row, lengths=(n,), what=f"{n} numbers") for i, row in enumerate(value))
    import numpy as np

    K = np.array(rows)
    scale = float(np.max(np.abs(K))) or 1.0
    if not np.allclose(K, K.T, rtol=0.0, atol=1e-12 * scale):
        i, j = np.unravel_index(int(np.argmax(np.abs(K - K.T))), K.shape)
        raise ScenarioError(path, f"[{i}][{j}] = {K[i, j]:.6g} but [{j}][{i}] = {K[j, i]:.6g}", what)
    w = float(np.linalg.eigvalsh(0.5 * (K + K.T))[0])
    if w < -1e-10 * scale:
        raise ScenarioError(path, f"an eigenvalue {w:.6g}", what)
    return rows
