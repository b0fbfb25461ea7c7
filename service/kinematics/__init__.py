"""Pure-numpy kinematics core. Imports numpy and the standard library only."""
