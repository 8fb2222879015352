"""Localization: RANSAC ego-motion and Hough-transform global localization (Lin et al.; Se et al.).

Modules: :mod:`.egomotion` (Lin et al. Sec. 4-7) and :mod:`.hough` (Se et al. Sec. 5). Depends on
:mod:`robokit.vision` and :mod:`robokit.mapping`, never on ``viz`` or ``sim``.
"""
