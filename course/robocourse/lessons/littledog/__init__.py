"""Lesson 04, the LittleDog quadruped as a system (LittleDog User Guide).

experiment  the lesson's tables: walks in MuJoCo under the servo and host loops, sensing, power
terrain     the terrain table: walks over step boards, blind and with the boards' map (true, MoCap-located)
data        assignment 04's data: the model's constants, simulated crawls with their true touchdowns, MoCap frames
exercises   assignment 04
"""
