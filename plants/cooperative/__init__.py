"""The cooperative system of docs/model.md section 5: arms rigidly holding the elastic system's contact nodes."""

from plants.cooperative.assembly import assemble_plant
from plants.cooperative.contact_point import ContactPoint
from plants.cooperative.control_terms import ControlTerms
from plants.cooperative.cooperative_plant import CooperativePlant
from plants.cooperative.loaded_state import nominal_node_motion, nominal_node_poses
from plants.cooperative.plant_args import PlantArgs

__all__ = ["assemble_plant", "ContactPoint", "ControlTerms", "CooperativePlant", "nominal_node_motion", "nominal_node_poses", "PlantArgs"]
