"""Outdoor navigation (lesson 05): NMEA 0183, geodesy, sonar, a skid-steer truck and its navigator.

Follows Hamid, Adom, Rahim and Rahiman, "Navigation of mobile robot using Global Positioning
System (GPS) and obstacle avoidance system with commanded loop daisy chaining application method"
(seed 000, question 3): an RC truck that drives GPS waypoints read from NMEA sentences ($GPRMC,
$GPRMB, $GPGGA, $HCHDG) and avoids obstacles with four LV-MaxSonar-EZ sensors fired in a
commanded daisy-chain loop.

Submodules
----------
nmea        checksum, typed records, a resynchronising stream reader
nmea_write  sentence builders (what a receiver model emits)
geodesy     haversine, tangent-plane projection, WGS84 inverse problem
sonar       LV-MaxSonar-EZ model, chained versus free-running firing, the paper's layout
field       the outdoor field with obstacles
truck       skid-steer kinematics with slip
controller  heading controller designed with python-control
gps         1 Hz GPS receiver and compass models that emit NMEA text
navigator   waypoint following plus the sonar obstacle-avoidance state machine, and the simulation
"""
