"""robokit: the reference library of the robokit courseware.

Mobile-robot perception, localization and robot kinematics, built from the course's source papers
(see ``README.md``). Subpackages, bottom layer first (``docs/DESIGN.md``; ``tests/test_layers.py``
enforces the order): ``geometry``; ``sim``, ``vision``; ``mapping``; ``localization``,
``controllers``; ``outdoor``, ``arm``; ``viz``; ``exercises``; ``grading``.

``robokit.FAST`` is true when ``ROBOKIT_FAST=1`` asks experiments to shrink (tests, course build);
``robokit.cache_dir()`` is where deterministic generated data are cached.
"""
from .config import FAST, fast_mode
from .cache import cache_dir, cache_key

__version__ = "0.1.0"

__all__ = ["FAST", "cache_dir", "cache_key", "fast_mode", "__version__"]
