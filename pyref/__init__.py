"""pyref: the standalone reference solver (numpy) the engines are checked against."""
from .laws import LawParams, normal_force, tangential_force
from .solver import Simulation

__all__ = ["LawParams", "Simulation", "normal_force", "tangential_force"]
