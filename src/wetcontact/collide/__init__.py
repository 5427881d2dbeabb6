"""Wet collisions: a sphere hitting a wall or another sphere through a liquid film, a
bridge or an immersing liquid, with any registered force model.

``collide(case)`` integrates the impact through its phases (penetration, solid contact,
emergence, bridge) and returns a frozen :class:`Collision` (restitution, outcome, phases,
energy budget). Cases are read by :func:`load_collision_case`.
"""

from wetcontact.collide.case import (
    CollisionCase,
    Impact,
    Solid,
    collision_case_from_dict,
    load_collision_case,
)
from wetcontact.collide.impact import ORDER, collide
from wetcontact.collide.result import Collision, Phase

__all__ = ["ORDER", "Collision", "CollisionCase", "Impact", "Phase", "Solid", "collide",
           "collision_case_from_dict", "load_collision_case"]
