"""Lesson 02, omnidirectional hierarchical localization and visual path following (Li et al. 2011).

experiment  the office: its tour, the topological map built from it (cached), the test poses and
            the route
landmarks   the map's landmarks from above (Fig. 8): where two nodes' feature rays cross
checks      the coarse-to-fine checks measured (widening, Monte-Carlo) and the histogram mask tried
alignment   when aligning the map beats odometry: loop sets kept, loop-edge errors, redrawn odometry
navigation  the autonomous runs along a recorded visual path from perturbed starts (cached)
benchmark   both map aligners on g2o's Intel Research Lab pose graph (shipped): cost, iterations, time
relaxation_runs  the relaxation loop exercise: office-tour pose graphs, the reference loop, its outcome
            check
exercises   assignment 02
"""
