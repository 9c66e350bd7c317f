"""``[[springs]]``: one elastic interconnection between two nodes (docs/model.md §3, (106-111))."""

from __future__ import annotations

from dataclasses import dataclass

from coopctrl.errors import ScenarioError
from coopctrl.scenario.checks import choice, number, scalar_or_vector
from coopctrl.scenario.schema import key, limits

ELEMENTS = ("central", "offset")
DAMPING_FORMS = ("frame_invariant", "book")


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
            springs; no lateral stiffness without pre-tension) or ``"offset"`` (rest offset fixed in
            the object frame, so it also has shear stiffness; docs/model.md §3, known limit).
        damping_form: ``"frame_invariant"`` (default: the dampers act on the rate of the deformation,
            the elongation in the element's frame and the relative angular velocity, so they do no
            work under a rigid motion; docs/model.md §3 [ours]) or ``"book"`` (110-111: world velocity
            differences and Euler-rate differences, as in the book).
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

    def stiffness_per_axis(self, space: str) -> tuple[float, ...]:
        """Translational stiffness per axis [N/m] (2 planar, 3 spatial)."""
        n = 2 if space == "planar" else 3
        return self.stiffness if isinstance(self.stiffness, tuple) else (self.stiffness,) * n

    def torsion_per_axis(self, space: str) -> tuple[float, ...]:
        """Torsional stiffness per axis [N m/rad] (1 planar, 3 spatial)."""
        n = 1 if space == "planar" else 3
        return self.torsion if isinstance(self.torsion, tuple) else (self.torsion,) * n
