"""The elastic system of docs/model.md section 3: nodes, interconnections, and their equations."""

from plants.elastic.elastic_system import ElasticSystem, pose_size
from plants.elastic.interconnection import Interconnection
from plants.elastic.node import Node

__all__ = ["ElasticSystem", "Interconnection", "Node", "pose_size"]
