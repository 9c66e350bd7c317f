"""Elastic structures from finite elements, as the book derives them (47)-(59): element
stiffness matrices, the connection matrices ``a_0``, ``a_1`` and ``a``, and the structure's
stiffness ``K = a^T K_e a`` (docs/model.md s.3).

This package builds the constant stiffness of the immobile unloaded state (4.5) from beams and
user matrices; it is numpy code run once when a scene is built, not in the hot path.
"""

from plants.elastic.fem.assembly import StiffnessAssembly, direct_stiffness, stiffness_assembly
from plants.elastic.fem.beam_element import planar_beam_stiffness, spatial_beam_stiffness
from plants.elastic.fem.elements import BeamElement, MatrixElement, line_frame

__all__ = ["BeamElement", "MatrixElement", "StiffnessAssembly", "direct_stiffness", "line_frame",
           "planar_beam_stiffness", "spatial_beam_stiffness", "stiffness_assembly"]
