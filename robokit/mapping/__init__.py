"""Mapping: the seeds' planar pose acting on 3-D points, and the Kalman-filtered landmark database.

Modules: :mod:`.frames` (pose ``[p, q, theta]``, backward transformation with covariance) and
:mod:`.landmarks` (Se, Lowe & Little Sec. 3). Depends on :mod:`robokit.vision`, never on
``viz`` or ``sim``.
"""
