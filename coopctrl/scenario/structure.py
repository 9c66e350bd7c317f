"""The springs checked as a structure: every grasp supported, no element numerically absent.

A field can be within its range and the structure still hold nothing: a ``matrix`` element of all
zeros leaves its contact node connected to nothing, a beam with ``Iy = 1e-300`` m^4 has no bending
stiffness about y, one with ``E = G = 1e-300`` Pa none at all. Such a scene would run, and diverge
with no cause a user could act on. :func:`check_structure` refuses it when the plant is built (so
``coopctrl check`` and ``coopctrl run`` alike, exit 2), naming the spring and the property.

The criterion, on the stiffness ``K`` of the immobile model (4.5; matrix and beam elements by their
linearization at rest, internal nodes condensed), :meth:`ElasticSystem.stiffness_matrix`: every node
``k`` (the object, and each contact node, which its arm holds) must be supported in translation by
the springs at it, with every other node held,

.. math::
    \\lambda_{min}(S_k) > \\mathrm{RTOL} \\cdot k_{ref}, \\qquad S_k = K[t_k, t_k],
    \\quad k_{ref} = \\max_k \\lambda_{max}(S_k)

``t_k``: node k's translational rows (x, y, z; planar x, z) [N/m]. ``S_k`` is the sum of the PSD
blocks of the springs at node k, so a direction ``v`` with ``v^T S_k v`` that small is one that no
spring at the node resists: its load goes unresisted, or through a stiffness :data:`RTOL` times the
scene's stiffest, whose force on a deflection of the scene's size is below the rounding error of the
other springs' forces in the same sum (double precision keeps 16 digits; 1e-10 leaves six for the
soft direction's force beside the stiff one's). A scene whose springs are all equally soft is not refused
here: its deflection under the load is what ``simulation.max_deformation`` stops at the start.

The property named: ``stiffness`` for a central or offset spring, ``matrix`` for a matrix element,
and for a beam the section property behind the unresisted direction (axial: ``E`` or ``A``; lateral:
``E``, ``Iy`` or ``Iz``), the one smallest against the top of its range in the scene reference.
"""

from __future__ import annotations

import numpy as np

from coopctrl.errors import ScenarioError

__all__ = ["RTOL", "check_structure"]

#: Smallest translational support of a node, relative to the stiffest node's [-] (module docstring).
RTOL = 1e-10

#: The top of each beam property's range in the scene reference (``SpringConfig``) [Pa, m^2, m^4].
_BEAM_TOP = {"E": 1.2e12, "G": 1.2e12, "A": 1.0, "Iy": 1.0, "Iz": 1.0, "J": 1.0}


def _translations(k: int, p: int) -> np.ndarray:
    return np.arange(k * p, k * p + (3 if p == 6 else 2))


def check_structure(scenario, elastic) -> None:
    """Raise :class:`~coopctrl.errors.ScenarioError` naming ``springs[e].<property>`` when a node of
    ``elastic`` (the scenario's :class:`~plants.elastic.ElasticSystem`) is not supported in translation
    (module docstring); else return ``None``."""
    p = elastic.p
    edges = [elastic.edge_stiffness(e) for e in range(len(elastic.interconnections))]
    n_nodes = elastic.node_count
    K = np.zeros((n_nodes * p, n_nodes * p))
    for dofs, block in edges:
        K[np.ix_(dofs, dofs)] += block
    supports = []
    for k in range(1 + len(scenario.arms)):
        t = _translations(k, p)
        S = 0.5 * (K[np.ix_(t, t)] + K[np.ix_(t, t)].T)
        w, V = np.linalg.eigh(S)
        supports.append((k, w, V))
    k_ref = max(float(w[-1]) for _, w, _ in supports)
    for k, w, V in supports:
        if float(w[0]) > RTOL * k_ref:
            continue
        v = V[:, 0]
        _refuse(scenario, elastic, edges, k, v, float(w[0]), k_ref)


def _node_name(k: int) -> str:
    return "the object (node 0)" if k == 0 else f"arm {k}'s contact node (arms[{k - 1}], node {k})"


def _refuse(scenario, elastic, edges, k: int, v: np.ndarray, least: float, k_ref: float) -> None:
    p = elastic.p
    axes = "xyz" if p == 6 else "xz"
    direction = "(" + ", ".join(f"{c}: {x:+.2f}" for c, x in zip(axes, v * np.sign(v[np.argmax(np.abs(v))]))) + ")"
    at = [e for e, (dofs, _) in enumerate(edges) if k * p in dofs]
    nt = len(v)
    if not at:
        raise ScenarioError("springs", f"no spring at node {k}",
                            f"a spring connecting {_node_name(k)} to the structure", scenario.source)
    # the spring resisting the direction least carries the blame (each one's share of v^T S_k v is >= 0)
    shares = []
    for e in at:
        dofs, block = edges[e]
        rows = np.flatnonzero(dofs == k * p)[0] + np.arange(nt)
        shares.append(float(v @ block[np.ix_(rows, rows)] @ v))
    e = at[int(np.argmin(shares))]
    spring = scenario.springs[e]
    prop, value = _property(scenario, elastic, e, k, v)
    others = [f"springs[{j}]" for j in at if j != e]
    besides = f" (with {', '.join(others)})" if others else ""
    allowed = (f"a value that supports {_node_name(k)}: with it the springs at that node{besides} resist a "
               f"translation along {direction} with {least:.3g} N/m, below {RTOL:g} x the scene's stiffest "
               f"support {k_ref:.3g} N/m, so the grasp is numerically unsupported there (docs/reliability.md, "
               "'Structures'); raise it, or add a spring that carries that direction")
    raise ScenarioError(f"springs[{e}].{prop}", value, allowed, scenario.source)


def _property(scenario, elastic, e: int, k: int, v: np.ndarray) -> tuple[str, object]:
    """The property of ``springs[e]`` behind its missing support of node ``k`` along ``v`` (module docstring)."""
    spring = scenario.springs[e]
    if spring.element in ("central", "offset"):
        return "stiffness", spring.stiffness
    if spring.element == "matrix":
        return "matrix", "a matrix that does not resist that translation"
    i, j = spring.pair
    n = len(v)
    Yr = elastic.Y_ref
    axis = np.asarray(Yr[j, :n], float) - np.asarray(Yr[i, :n], float)
    axis = axis / (np.linalg.norm(axis) or 1.0)
    axial = abs(float(v @ axis)) > np.sqrt(0.5)
    names = ("E", "A") if axial else (("E", "Iy", "Iz") if n == 3 else ("E", "Iy"))
    ratios = {name: getattr(spring, name) / _BEAM_TOP[name] for name in names if getattr(spring, name) is not None}
    name = min(ratios, key=ratios.get)
    return name, getattr(spring, name)
