"""Robot kinematics service: forward kinematics and every inverse-kinematics solution."""

__version__ = "0.1.0"
