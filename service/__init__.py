"""Robot kinematics service: forward kinematics and every inverse-kinematics solution."""
