"""LittleDog quadruped: model, kinematics, gaits, sensing, simulation, trial logs, power (lesson 04)."""
# gaits: support polygon and stability margin, gait schedules, crawl and trot plans
from .gait import WalkPlan, swing_trajectory, walking_plan
from .gait_schedule import CRAWL_SEQUENCE, TROT_PAIRS, GaitSchedule, crawl_gait, stance_pattern, trot_gait
from .support import SupportPolygonError, stability_margin, stability_margins, support_polygon

__all__ = [
    # gaits
    "SupportPolygonError", "support_polygon", "stability_margin", "stability_margins", "GaitSchedule", "crawl_gait",
    "trot_gait", "stance_pattern", "swing_trajectory", "WalkPlan", "walking_plan", "CRAWL_SEQUENCE", "TROT_PAIRS",
]
