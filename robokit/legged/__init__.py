"""LittleDog quadruped: model, kinematics, gaits, sensing, simulation, trial logs, power (lesson 04)."""
# gaits: support polygon, stability margin, crawl and trot plans
from .support import SupportPolygonError, stability_margin, stability_margins, support_polygon

__all__ = [
    # gaits
    "SupportPolygonError", "support_polygon", "stability_margin", "stability_margins",
]
