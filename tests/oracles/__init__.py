"""Independent test oracles: textbook closed forms, free of any DH product code and of the service's solver.

``closed_forms``: forward kinematics written out entry by entry (see it for which robots are covered).
``textbook_ik``: the textbook's inverse kinematics, every branch, with its names for the branches.
``opw``: the OPW arms' forward kinematics from their seven parameters, and the catalogue OPW arms' sources.
``paths``: tool paths with exact derivatives and a Jacobian by FK differences, for the trajectory tests.
``q6_arcs``: the arcs of q6 a UR-type arm reaches with at its wrist singularity, by FK alone.
``rotations``: Rodrigues' formula, rotations about x, y, z, roll-pitch-yaw, quaternions, random rotations.
"""

from tests.oracles.closed_forms import CLOSED_FORMS, ORACLE_PARAMETERS
from tests.oracles.textbook_ik import TEXTBOOK_IK

__all__ = ["CLOSED_FORMS", "ORACLE_PARAMETERS", "TEXTBOOK_IK"]
