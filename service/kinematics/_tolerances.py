"""The one place for numerical tolerances used by the core.

Detection of special cases (singularities, parallel or intersecting axes,
reachability limits) always goes through these tolerances, never through exact
float equality.
"""

from __future__ import annotations

import numpy as np

#: Largest deviation from orthonormality accepted in an input rotation,
#: measured as max |R^T R - I| and |det R - 1|.
ORTHONORMAL_TOLERANCE = 1e-6

#: Relative tolerance for geometric tests on unit vectors (parallel axes,
#: intersecting axes, zero-length projections).
GEOMETRY_TOLERANCE = 1e-9

#: What an angle found at a double root (a fold: a stretched elbow, two cones that touch) is known to when its
#: inputs are known to GEOMETRY_TOLERANCE: the square root of it (relative).
FOLD_TOLERANCE = float(np.sqrt(GEOMETRY_TOLERANCE))

#: Geometry as CAD exports and vendors state it: axes within this angle (radians) of parallel, intersecting or
#: perpendicular, or lines within this fraction of the arm's size of meeting, are recognised as exactly so.
#: The closed form then solves the idealised arm and every candidate is refined and verified on the true arm
#: (see :mod:`.ik._idealised`, which also decides when that answer is still complete). π/2 written 1.5708 is
#: 7e-6 rad off and a length rounded to 0.1 mm at most 5e-5 of a 1 m arm; vendors' URDFs write rpy angles to
#: three decimals (Doosan: 1.571, 2.0e-4 rad off; 3.142 is 4.1e-4 off), which sets this bound.
RECOGNITION_TOLERANCE = 5e-4

#: An arm whose relations hold within exact recognition (``10 GEOMETRY_TOLERANCE``) but not within this (radians,
#: or fraction of the arm's size) is solved as an idealised arm (see :mod:`.ik._idealised`): a closed form that
#: assumes them errs by a few times the deviation, and near a singularity by far more (a double root by its square
#: root, an angle seen on a small radius by the deviation over the radius), beyond what its FK check's polish can
#: mend. URDFs written to nine or more digits deviate by ~1e-11; one written to eight, by ~1e-9.
EXACT_DEVIATION = 1e-10

#: An IK solution is accepted when its FK position error is below this
#: fraction of the robot's characteristic length, and its orientation error
#: (radians) below the same number.
ACCEPT_RESIDUAL = 1e-9

#: Candidates whose residual is below this (same units) but above
#: ACCEPT_RESIDUAL get a few Gauss–Newton steps before the FK check: near a
#: singularity a closed form loses digits that one Newton step restores.
POLISH_RESIDUAL = 1e-4

#: Two solutions closer than this (radians, or fraction of the characteristic
#: length for prismatic joints) are the same solution.
DUPLICATE_TOLERANCE = 1e-6

#: Inclusive-bound tolerance of joint limits: radians for revolute joints; times the robot's
#: characteristic length for prismatic joints.
LIMIT_TOLERANCE = 1e-9

#: Relative rounding error of a target pose computed by FK, and of quantities formed from it in a few
#: operations (64 ulps). At a fold of a positioner (two solutions meeting) a coordinate of the solution is
#: seen only through a square: a target rounded to this fraction of its size leaves it undetermined within
#: a band, and the solver takes the reference's value when it lies in that band (see
#: ``IntersectingShoulder`` with a slide through axis 2).
ROUNDING_TOLERANCE = 64 * float(np.finfo(float).eps)
#: A configuration is reported as singular when the relevant quantity (a sine,
#: a normalised distance) is smaller than this.
SINGULARITY_TOLERANCE = 1e-7

#: Joint rates are reported as singular (NaN, or damped least squares on
#: request) where the smallest singular value of the scaled task Jacobian is
#: below this (see :mod:`._rates`): the joint rates would be more than about a
#: thousand times the task rate, in units of the robot's size.
RATE_SINGULARITY_TOLERANCE = 1e-3
