"""Independent test oracles: textbook closed forms, free of any DH product code.

See ``closed_forms`` for which robots are covered and which are left out.
"""

from tests.oracles.closed_forms import CLOSED_FORMS, ORACLE_PARAMETERS

__all__ = ["CLOSED_FORMS", "ORACLE_PARAMETERS"]
