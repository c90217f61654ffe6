"""Model files: MJCF (and, later, URDF) into a plain description of bodies, joints and geoms, then into tumble.

``mjcf/`` reads a file (parse the XML, expand ``include``, resolve ``default`` classes and ``compiler`` settings) into
a :class:`~tumble.models.description.ModelDescription`; ``build.py`` turns a description into an
:class:`~tumble.articulation.Articulation`. MuJoCo is the oracle for what an MJCF file means: the tests compare the
description and the articulation with MuJoCo's compiled model of the same file.
"""
