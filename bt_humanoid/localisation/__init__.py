"""Where the robot is on its map: odometry that drifts, corrected against the map by the base scanner.

``odometry.py`` turns what the base's wheels measure into pose increments, with the errors wheels make;
``scan_map.py`` is the map the scanner is matched against (a signed distance field of the fixed geometry at
the scanner's height); ``scan_matcher.py`` finds the pose that lays a scan onto it; ``localiser.py`` fuses the
two (an extended Kalman filter) and notices when the robot no longer knows where it is.
"""
