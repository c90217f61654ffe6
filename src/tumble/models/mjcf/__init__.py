"""MJCF, MuJoCo's model format: a file or XML text into a :class:`~tumble.models.description.ModelDescription`.

Four stages, each in its own module: ``xml`` (the tree with file and line of every element, ``include``
expanded), ``resolve`` (``compiler`` settings, ``default`` classes, every attribute resolved; mass properties from
``inertial`` or the geoms, in ``inertia``; mesh assets in ``meshes``, their inertia in ``mesh_inertia``), ``springs``
(``springdamper`` sized once the tree is known), and the plain description it returns.
"""

from __future__ import annotations

import os

from ..description import ModelDescription
from .resolve import MJCFWarning, describe
from .springs import sized_springs
from .xml import MJCFError, read_model

__all__ = ["MJCFError", "MJCFWarning", "read_mjcf"]


def read_mjcf(path_or_xml: str | os.PathLike) -> ModelDescription:
    """The description of an MJCF file (a path) or of MJCF text (a string starting with ``<``).

    Raises:
        MJCFError: malformed XML, a missing or looping ``include``, or an element that cannot be read; the message
            names the file, the element and its line.
    """
    root, base = read_model(path_or_xml)
    return sized_springs(describe(root, base))
