"""Lesson 01, stereo visual SLAM with PLOT and SIFT features (Lin et al.; Se, Lowe & Little 2002).

experiment  Se et al.'s Sec. 6 re-run in the simulated lab: the calibrated rig, the mapping lap,
            the map and the kidnapped test poses (cached), and the map's consistency check
odometry    stretches of the lab lap as stereo features and matches per frame, without rendering
            (the loop exercise's runs)
odometry_loop  the loop exercise: robust frame-to-frame poses chained, its cases, judge and shortcuts
exercises   assignment 01
"""
