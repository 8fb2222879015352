"""Lesson 03, coarse-to-fine localization in a long corridor (Ge et al. 2023).

experiment  the lesson's laser and camera; the calibration video, the vocabulary, the hybrid map
            (each cached)
orb_realism  ORB on our views against a real photograph; feature counts before and after ORB's cap
trials      Table 2's runs, AMCL against the retrieval-started MCL (cached), and their records
kidnapping  Fig. 15's kidnapped robot
real_map    the same AMCL on a real building's map (Willow Garage, ROS navigation tutorials) and in the
            corridor (cached)
repetition  AMCL in corridors of graded clutter, with ROS's default and TurtleBot 2's amcl settings (cached)
aliasing    one scan and the poses a laser-only filter confuses it with (assignment 03's question)
mcl_runs    short drives in the corridor as plain data, for assignment 03's loop exercise
exercises   assignment 03
"""
