"""The course's one setting: fast mode, read from ``ROBOKIT_FAST`` (:func:`robokit.config.fast_mode`)."""
from robokit.config import fast_mode

__all__ = ["FAST"]

#: Fast mode as read once at import time: the lessons' experiments shrink (fewer trials, smaller
#: images) so that a notebook runs in seconds. Set by the test-suite and ``robocourse build --fast``.
FAST: bool = fast_mode()
