"""Independent test oracles: textbook closed forms, free of any DH product code and of the service's solver.

``closed_forms``: forward kinematics written out entry by entry (see it for which robots are covered).
``textbook_ik``: the textbook's inverse kinematics, every branch, with its names for the branches.
``opw``: the OPW arms' forward kinematics from their seven parameters, and the catalogue OPW arms' sources.
"""

from tests.oracles.closed_forms import CLOSED_FORMS, ORACLE_PARAMETERS
from tests.oracles.textbook_ik import TEXTBOOK_IK

__all__ = ["CLOSED_FORMS", "ORACLE_PARAMETERS", "TEXTBOOK_IK"]
