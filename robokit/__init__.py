"""robokit: the reference library of the robokit courseware.

Mobile-robot perception, localization and robot kinematics, built from the course's source papers
(see ``README.md``). Topic subpackages: ``geometry``, ``sim``, ``vision``, ``mapping``,
``localization``, ``controllers``, ``legged``, ``outdoor``, ``arm``, ``viz``, ``grading``.

``robokit.FAST`` is true when ``ROBOKIT_FAST=1`` asks experiments to shrink (tests, course build);
``robokit.cache_dir()`` is where deterministic generated data are cached.
"""
from .config import FAST, cache_dir, cache_key, fast_mode

__version__ = "0.1.0"

__all__ = ["FAST", "cache_dir", "cache_key", "fast_mode", "__version__"]
