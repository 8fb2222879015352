"""robokit: the reference library of the robokit courseware.

Mobile-robot perception, localization, legged systems and robot kinematics, built from the course's
source papers (see ``README.md``). Each subpackage's docstring is its map; bottom layer first
(``tests/test_layers.py`` enforces the order): ``geometry``; ``vision``; ``sim``; ``mapping``;
``localization``, ``controllers``; ``legged``, ``outdoor``, ``arm``, ``navigation``; ``viz``.
The course around it (lessons' experiments, exercises, grading, the site) is the separate
``robocourse`` package.
"""
__version__ = "0.1.0"

__all__ = ["__version__"]
