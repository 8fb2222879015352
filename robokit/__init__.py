"""robokit: the reference library of the robokit courseware.

Mobile-robot perception, localization, legged systems and robot kinematics, built from the course's
source papers (see ``README.md``); every function cites the paper and equation it implements. The
course around it (the lessons' experiments, exercises, grading, the site) is the separate
``robocourse`` package. Subpackages and modules, bottom layer first (``tests/test_layers.py``
enforces the order); each subpackage's docstring maps its modules:

validation    the input checks every public function uses (errors that name the argument)
config        settings from the environment: headless, fast mode, worker processes
files         bounded file readers and atomic writers (.npz round trips)
cache         the dataset cache (keys, meta, rebuilds)
progress      the one progress bar of every long step
parallel      independent, separately seeded runs in worker processes
geometry      SE(2), SO(3), SE(3), rigid fits, the papers' frames
vision        features (PLOT, SIFT, ORB), matching, stereo, colour, bags of words
sim           textured worlds, cameras, LiDAR, vehicles, motion, recorded runs
mapping       landmark databases, pose graphs, topological maps, occupancy grids, corridor scans
localization  ego-motion, global localization, visual SLAM, hierarchical and Monte-Carlo localization
controllers   control loops designed with python-control: servos, heading, path following
legged        the LittleDog quadruped: model, kinematics, gaits, sensing, MuJoCo simulation
outdoor       NMEA, geodesy, sonar, a skid-steer truck and its navigator
arm           DH chains, Jacobians, analytic and numeric IK of redundant arms
navigation    closed-loop navigation along a visual path
viz           meshcat scenes and matplotlib figures
"""
import warnings

from .config import pad_heap

__version__ = "0.1.0"

__all__ = ["__version__"]

try:            # freed arrays stay mapped: a filter update over thousands of particles takes half the time
    pad_heap()
except ValueError as exc:       # a speed setting's typo must not stop every import: say so and go on
    warnings.warn(f"{exc}; the C heap is left as it is", RuntimeWarning, stacklevel=2)
