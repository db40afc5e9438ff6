# SPDX-License-Identifier: GPL-2.0-or-later
"""pyref: the standalone reference solver (numpy) the engines are checked against."""
from .laws import LawParams, TangentialStep, normal_force, tangential_force
from .solver import ENERGY_FIELDS, Contacts, Recording, Simulation

__all__ = ["ENERGY_FIELDS", "Contacts", "LawParams", "Recording", "Simulation", "TangentialStep", "normal_force",
           "tangential_force"]
