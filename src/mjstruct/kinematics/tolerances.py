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
