"""The plants' compiled (numba) kernels and their constants, by public name.

The classes of :mod:`plants.arms`, :mod:`plants.elastic` and :mod:`plants.cooperative` wrap these for
Python use; a caller that composes its own compiled code (and an independent check of the fused
right-hand sides, such as the test suite's reference) calls them directly. Each is an ``@njit``
function taking and filling plain float64 arrays; the arguments are documented on the function.

Arms (docs/model.md s.4):

* :func:`chain_arm_terms` - ``H``, ``h``, ``Y = Phi(q)``, ``J`` and ``dJ dq`` of a general serial chain
  (URDF and DH arms alike); :data:`COULOMB_SMOOTHING` [m/s or rad/s] is the rate scale of its smooth
  Coulomb friction ``coulomb * tanh(dq / COULOMB_SMOOTHING)``; :func:`chain_arm_terms_own_chart` the same
  with the node's angles in its own chart (``A = 0``, the chart ``R_tip(q)`` returned; docs/model.md s.2);
* :func:`planar_arm_terms` - the same for a planar arm.

Elastic system (docs/model.md s.3):

* :func:`node_terms`, :func:`solve_node_rotation` - a spatial node's mass terms and its rotational solve;
* :func:`interconnection_terms` / :func:`planar_interconnection_terms` - the interconnections' forces on
  the nodes (spatial / planar);
* :data:`STATUS_OK`, :data:`STATUS_EULER_SINGULAR`, :data:`STATUS_COINCIDENT_NODES`,
  :data:`STATUS_SINGULAR_MASS` - the status codes the kernels write.

Linear algebra: :func:`cholesky_solve` - ``A x = b`` for a symmetric positive-definite ``A``, in place.
"""

from __future__ import annotations

from plants.arms._chain_kernels import COULOMB_SMOOTHING, chain_arm_terms, chain_arm_terms_own_chart
from plants.arms._planar_kernels import planar_arm_terms
from plants.cooperative._linalg import cholesky_solve
from plants.elastic._layout import STATUS_COINCIDENT_NODES, STATUS_EULER_SINGULAR, STATUS_OK, STATUS_SINGULAR_MASS
from plants.elastic._planar_kernels import interconnection_terms as planar_interconnection_terms
from plants.elastic._spatial_kernels import interconnection_terms, node_terms, solve_node_rotation

__all__ = [
    "COULOMB_SMOOTHING", "STATUS_COINCIDENT_NODES", "STATUS_EULER_SINGULAR", "STATUS_OK", "STATUS_SINGULAR_MASS",
    "chain_arm_terms", "chain_arm_terms_own_chart", "cholesky_solve", "interconnection_terms", "node_terms", "planar_arm_terms",
    "planar_interconnection_terms", "solve_node_rotation",
]
