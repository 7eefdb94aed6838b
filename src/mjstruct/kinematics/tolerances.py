"""The tolerances of the kinematics plug-in, named once.

Owns every threshold the position analysis compares against: when two centres
coincide, when a triangle still assembles, when two guides are parallel, when a
Jacobian is near singular, and how tightly the closure equations are solved.  Lengths
are relative to the mechanism's size (:attr:`~mjstruct.kinematics.geometry.Geometry.scale`)
unless said otherwise; sines and discriminants are dimensionless.

Examples
--------
>>> COINCIDE < DISC_SLACK * 1e3 < NEAR_SINGULAR
True
"""

from __future__ import annotations

#: two joint centres closer than this (relative to the mechanism's size) coincide
COINCIDE = 1e-12
#: a triangle's discriminant in (-DISC_SLACK, 0) is rounding of a touching triangle: 0
DISC_SLACK = 1e-12
#: the two centres of a dyad RRR closer than this (relative to r1 + r2): undefined dyad
CENTRES_APART = 1e-10
#: |sine| between two guides below this along the motion: parallel, no intersection
PARALLEL = 1e-12
#: |sine| between two guides of a dyad PRP / RPP at the reference below this: bad input
PARALLEL_REF = 1e-9

#: |det| of the driver-fixed Jacobian below this fraction of its largest value: flagged
NEAR_SINGULAR = 1e-3
#: singular values below this times the largest (and the matrix size) count as zero
RANK_RTOL = 1e-10
#: rank tolerance (relative to the size) of the Jacobian that refines the planner's DOF
PLAN_RANK_TOL = 1e-9
#: a redundant constraint holds along the motion when its residual is below this
REDUNDANT_HOLDS = 1e-9

#: default closure tolerance, relative to the mechanism's size
CLOSURE_TOL = 1e-12
#: smallest closure tolerance accepted: a few ulps of the size (double precision
#: resolves 2.2e-16 of it); below, Newton cannot tell convergence from rounding
TOL_FLOOR = 1e-15
#: the closure's own default (Newton stops there; the model asks for CLOSURE_TOL)
NEWTON_TOL = 1e-13
#: a frame whose Newton iteration stalls (no longer halves its error) counts as closed
#: when its error is within this factor of the tolerance (the rounding floor)
STALL_ERROR = 1e3
#: continuation stations never closed more loosely than this
STATION_TOL = 1e-10
#: largest continuation step along the path (radians of the driver, or scale units)
STATION_STEP = 0.25

#: a refined |sine| below this means the two branches meet (a change point)
MEET = 1e-6
#: a frame's |sine| below this (and V-shaped against its neighbours) is examined
WATCH = 0.2

# Singular positions (singular.py, singular_curve.py, clearance.py): lengths over the
# mechanism's size, angles in rad, unit tangents and null vectors.

#: the reference closes when its residual is below this (file coordinates are rounded)
REF_CLOSES = 1e-9
#: the second-smallest singular value of J below this: J drops rank (a change point)
RANK_DROP = 1e-9
#: a Newton step below this stops the corrector: quadratic convergence leaves ~1e-14
STEP_CONVERGED = 1e-7
#: a corrector out of iterations still accepts a residual below this (near a change
#: point J is nearly singular and Newton converges slowly)
CORRECT_ACCEPT = 1e-11
#: central-difference step of second derivatives: truncation h^2 ~ 1e-8 balances
#: rounding eps / h^2 ~ 2e-8
FD_STEP2 = 1e-4
#: two configurations closer than this (max norm, angles wrapped) are one point; the
#: located positions agree to ~1e-13, so this only merges duplicates
SAME_POINT = 1e-7
#: a limit or extreme located this close to a change point is that change point (the
#: minors vanish there too)
AT_CHANGE_POINT = 1e-6
#: a sign change that cannot be located this close to a change point is the crossing
#: itself (the component jumps sign with the branch), not a lost root
NEAR_CHANGE_POINT = 0.1
#: a tangent component below this along a whole branch: the minor vanishes identically
#: (a fold arc)
FOLD_TOL = 1e-9
#: a tangent component below this fraction of its largest value along the branch is
#: zero at that station (a station lying exactly on a singular position)
ROOT_AT_STATION = 1e-12
#: a tangent component this small at a bracketing sample is the root itself
ROOT_ABS = 1e-14
#: two joints closer than this all along a fold branch sit on each other
COINCIDE_ALONG = 1e-9
#: three centres are in line when the triangle's sine is below this
COLLINEAR_TOL = 1e-7
#: a link's angle share of the unit singular direction above this: the link turns
TURNS = 1e-6
#: two q values (rad, or size units) closer than this touch: intervals are merged
Q_TOUCH = 1e-12
#: a q span within this of 2 pi is a full turn
FULL_TURN_SLACK = 1e-9
#: the branch-direction quadratic: all coefficients below this (before scaling) mean
#: every direction closes (more than one DOF); scaled ones below ZERO are zero
QUAD_DEGENERATE = 1e-6
QUAD_ZERO = 1e-9
#: tangents with |cos| above this are one direction (a branch through a change point)
SAME_DIRECTION = 0.95
#: a continuation step whose tangent turns by more than acos(0.9) ~ 26 deg is too long
STEP_TURN = 0.9
#: the continuation step below which tracing gives up
MIN_STEP = 1e-9
#: a residual curvature below this: no quadratic growth, the zone is the whole turn
ZONE_FLAT = 1e-12
#: the exact zone's solution is accepted with the closure and the discs to these
ZONE_CLOSURE = 1e-10
ZONE_DISC = 1e-8
#: values below this are shown as 0 in the text report (no "-0.000000")
DISPLAY_ZERO = 1e-9
#: largest clearance accepted: the zone formulas square (r + D), which must fit a double
MAX_CLEARANCE = 1e150
