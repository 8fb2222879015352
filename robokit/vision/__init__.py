"""Vision: PLOT and SIFT features, descriptor matching, evaluation and rectified stereo.

Modules: :mod:`.features` (containers), :mod:`.plot` (Lin et al. Sec. 2.i),
:mod:`.descriptors` (Lin et al. Sec. 2.ii, Se et al. Sec. 4, OpenCV SIFT), :mod:`.matching`
(Lin et al. Sec. 3), :mod:`.evaluation` (recall vs 1-precision), :mod:`.stereo` (Lin et al. Sec. 3,
Se et al. Sec. 2.2 and 3.1). Vision depends only on :mod:`robokit.geometry` and
:mod:`robokit.validation`.
"""
