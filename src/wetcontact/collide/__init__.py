"""Wet collisions: a sphere hitting a wall or another sphere through a liquid film, a
bridge or an immersing liquid, with any registered force model.

``collide(case)`` integrates the impact through its phases (penetration, solid contact,
emergence, bridge) and returns a frozen :class:`Collision` (restitution, outcome, phases,
energy budget). Cases are read by :func:`load_collision_case` or built from a scene by
:func:`collision_case`; :func:`restitution_map` gives many impacts of one geometry at
once. The package itself is callable: ``wetcontact.collide(case)`` is
``wetcontact.collide.collide(case)``.
"""

import sys
import types
from typing import Any

from wetcontact.collide.batch import BatchResult, restitution_map
from wetcontact.collide.case import (
    CollisionCase,
    Impact,
    Solid,
    collision_case,
    collision_case_from_dict,
    load_collision_case,
)
from wetcontact.collide.impact import ORDER, collide
from wetcontact.collide.result import Collision, Phase

__all__ = ["ORDER", "BatchResult", "Collision", "CollisionCase", "Impact", "Phase", "Solid",
           "collide", "collision_case", "collision_case_from_dict", "load_collision_case",
           "restitution_map"]


class _CallableModule(types.ModuleType):
    """This package, callable as :func:`collide`."""

    def __call__(self, *args: Any, **kwargs: Any) -> Collision:
        return collide(*args, **kwargs)


sys.modules[__name__].__class__ = _CallableModule
