"""Named numerical tolerances, in one place.

Each constant says what it bounds. Relative tolerances are dimensionless.
"""

#: Newton on the inverse map stops when its decrement is below ``INVERSE_RTOL**2 * h``: the
#: twist is then accurate to about ``INVERSE_RTOL`` and the safety factor to its square.
INVERSE_RTOL = 1e-12

#: Most Newton iterations of the inverse map before it gives up (per query).
INVERSE_MAX_ITERATIONS = 100

#: A load whose safety factor is at least ``1 - CONTAINMENT_RTOL`` counts as held.
CONTAINMENT_RTOL = 1e-9

#: Relative tolerance of the facet test of point supports: a load is taken to lie on the facet of
#: a support point when the force that point must carry exceeds its friction limit by less than
#: this fraction.
FACET_RTOL = 1e-12

#: Relative step of the central differences that give Hessians of closed-form support functions
#: (the Hessian only steers Newton's method; the answer is fixed by the exact gradient).
HESSIAN_STEP = 1e-6

#: A centre of rotation farther than this many patch radii from the patch is "far": the exact
#: closed forms lose digits to cancellation there, so Gauss quadrature of the (then analytic)
#: integrand is used instead.
FAR_FIELD_RADII = 4.0

#: Largest relative disagreement of a user's pressure or friction function's two quadrature
#: rules (about a centre of rotation near the patch, and fixed), probed where both apply: smooth
#: fields agree to 1e-14; steps, kinks and peaks too narrow for the rules disagree by 1e-5 to 1
#: (their answers are off by as much, and the inverse map often fails to converge on them).
QUADRATURE_RTOL = 1e-6

#: The planner's equilibrium residual must be below this fraction of the largest wrench term.
EQUILIBRIUM_RTOL = 1e-6

#: A contact wrench may exceed its friction set by this fraction before verification fails.
FRICTION_SET_RTOL = 1e-6

#: Contact loads of exact friction models lie inside their exact limit surfaces to this relative
#: excess (``1 / s - 1``) in a plan: the planner adds tangent-plane cuts until they do.
EXACT_CUT_RTOL = 1e-9

#: Exact sets stated as convex constraints (point supports, a cone per point) are shrunk by this
#: fraction, so that a solver's feasibility error (about 1e-9) leaves no load outside the exact
#: set by more than ``EXACT_CUT_RTOL`` (as the planner's cuts and ellipsoids are tightened).
STATED_SET_MARGIN = 1e-8

#: Fixed-force objectives cap each load scale here; a case that reaches the cap is reported with
#: an infinite safety factor (held at any practical multiple). A higher cap makes the conic
#: problems badly scaled (reactions a million times the loads).
MAX_SAFETY_FACTOR = 1e3

#: A largest multiple within this fraction of ``MAX_SAFETY_FACTOR`` is reported as at the cap
#: (infinite): the solver's accuracy.
CAP_RTOL = 1e-6

#: A case of a block whose largest multiple is within this fraction of ``MAX_SAFETY_FACTOR``
#: counts as carried at the cap when its block mates are solved again without it (see
#: :mod:`fixplan.planner.runner`): inaccurate answers leave capped cases at 999.75 to 1039.
CAPPED_BLOCK_RTOL = 1e-3

#: Smallest eigenvalue of a fitted ellipsoid's matrix in normalised coordinates: keeps the fit
#: positive definite (a bounded set) when the data leave a direction unconstrained.
FIT_MIN_EIGENVALUE = 1e-6

#: A component of the normalised force at maximum moment (or of the centre of pressure, in
#: units of the characteristic length) below this is rounding noise of a symmetric pressure
#: field; the ellipsoid, cone and pyramid are then not tilted (not moved).
TILT_ATOL = 1e-12

#: A model overestimates the limit surface ("unsafe") in a direction where its radius exceeds
#: the exact one by more than this fraction (the exact inverse map is accurate to ~1e-15).
UNSAFE_RTOL = 1e-9

#: A load case counts as held when its safety factor is at least ``1 - HELD_RTOL``; load cases
#: whose safety factors agree within it are tied. Ten times the verification tolerances: a
#: least-force plan that passed verification re-checks to within about 1e-6 of 1.
HELD_RTOL = 1e-5

#: Screw-axis points closer than this fraction of the body's length scale to a coordinate
#: plane are printed on it (solver noise).
SCREW_PRINT_RTOL = 1e-6

#: Where Newton stalls (integrands that are not smooth, e.g. a friction coefficient that jumps
#: across the patch, where the quadrature's rounding limits the last digits), the inverse map's
#: answer is accepted when its projected gradient is below this fraction of h — the safety
#: factor is then accurate to about 1e-10 and the motion to about 1e-5 rad; otherwise it raises
#: ConvergenceError instead of guessing.
INVERSE_GRADIENT_RTOL = 1e-5

#: Ends of a held interval of task-load multiples below this are 0 (solver noise).
MULTIPLE_ATOL = 1e-7

#: Passive normal forces that squeeze each other by less than this fraction of the largest
#: passive normal force of the load case are solver noise, not a squeeze.
SQUEEZE_RTOL = 1e-6

#: A point (and multipliers) of a conic program found without solving it, carried from the solve
#: of another (:mod:`fixplan.planner.optimality`), counts as feasible (and optimal) when its
#: residuals and duality gap are below this fraction of their terms: ten times Clarabel's own
#: tolerances in the planner (1e-9), since the carried point was solved to those in the other
#: program.
CERTIFICATE_RTOL = 1e-8

# -- Accepted ranges of inputs ------------------------------------------------------------------
# Physically generous bounds, checked where values enter (problem files, Problem, the command
# line), so that arithmetic never overflows and problem sizes stay within seconds of work.

#: Largest coordinate, position or patch dimension [m] (a kilometre).
MAX_LENGTH = 1e3

#: Largest force [N] (a load, a clamp or finger force, its bound; about 100,000 t-force).
MAX_FORCE = 1e9

#: Largest torque [N m] of a load: ``MAX_FORCE`` at ``MAX_LENGTH``.
MAX_TORQUE = MAX_FORCE * MAX_LENGTH

#: Largest body mass [kg] (10,000 t).
MAX_MASS = 1e7

#: Largest gravitational acceleration [m/s²] (about 100 g).
MAX_ACCELERATION = 1e3

#: Smallest mass [kg] (a microgram) and gravity [m/s²] of a pushed part: its support's normal
#: force, their product, must stay far above where the limit surface's arithmetic underflows
#: (a part of 1e-300 kg ended in an overflow).
MIN_PUSHED_MASS, MIN_PUSHED_GRAVITY = 1e-9, 1e-6

#: Largest density [kg/m³] of a body read from a mesh (osmium, the densest element: 22,590).
MAX_DENSITY = 1e5

#: Largest angular velocity [rad/s] of a load's body motion (about 100,000 rpm).
MAX_ANGULAR_VELOCITY = 1e4

#: Largest angular acceleration [rad/s²] of a load's body motion.
MAX_ANGULAR_ACCELERATION = 1e6

#: Largest entry of an inertia tensor [kg m²] (``MAX_MASS`` at ``MAX_LENGTH``).
MAX_INERTIA = MAX_MASS * MAX_LENGTH**2

#: An inertia tensor's asymmetry and its principal moments' breach of the triangle inequality
#: may be this fraction of its largest entry (rounding of a tensor typed or computed elsewhere).
INERTIA_RTOL = 1e-9

#: Largest friction coefficient (real ones are below about 5; a gecko pad is about 10).
MAX_MU = 100.0

#: Smallest positive friction coefficient: below it friction is numerical noise against the
#: normal forces (give 0 for a frictionless contact where the model allows it).
MIN_MU = 1e-6

#: Largest contact stiffness of a problem file [N/m, torsional N m/rad] (a steel contact a
#: metre across is about 1e12 N/m).
MAX_STIFFNESS = 1e13

#: Smallest positive contact stiffness of a problem file [N/m, torsional N m/rad]: softer
#: springs leave a compliant analysis too badly scaled to solve (give 0 for no tangential or
#: torsional spring).
MIN_STIFFNESS = 1e-6

#: Most facets of a pyramid model.
MAX_FACETS = 64

#: Longest name of a contact or load case, in characters (names become report file names).
MAX_NAME_LENGTH = 100

#: Most vertices of a polygon patch (the exact model's cost grows with the square).
MAX_POLYGON_VERTICES = 256

#: Most support points of a ``points`` patch.
MAX_POINTS = 4096

#: Most cells of a ``grid`` patch (a 64 × 64 tactile array).
MAX_GRID_CELLS = 4096

#: Largest magnitude of a relative weight or pressure (points' weights, grid values): they are
#: ratios, so any scale will do, and sums of up to ``MAX_GRID_CELLS`` of them stay finite.
MAX_RELATIVE_VALUE = 1e12

#: Smallest patch dimension [m] (a nanometre): below it the limit surface's arithmetic
#: underflows.
MIN_PATCH_LENGTH = 1e-9

#: Smallest normal force and smallest largest-friction-force ``mu N`` [N] of a limit surface: the
#: inverse map squares loads of that size (at 1e-200 N its safety factors came out NaN, at
#: 1e-150 N right).
MIN_FRICTION_FORCE = 1e-100

#: Largest ratio of a rectangle patch's sides (the inverse map loses accuracy on needles).
MAX_ASPECT_RATIO = 1e5

#: Largest ``inner_radius / radius`` of an annulus. Its closed form is the difference of two
#: uniform disks weighted ``1 / (1 - s²)`` and ``s² / (1 - s²)`` (``s`` this ratio), which
#: multiplies their rounding by ``1 / (1 - s²)``: at ``s = 0.999`` support values and
#: ``max_moment`` within 2e-14 of exact, ``safety_factor(load(V))`` within 1.4e-12 of 1 and no
#: failure of the inverse map in 5,000 random loads; at 0.9999 the line search of Newton's method
#: meets that rounding (a load whose inverse map fails), at ``1 - 1e-12`` ``max_moment`` is
#: 2.5e-5 off. A ring this thin is the profile ``"ring"`` to within its relative thickness.
MAX_ANNULUS_RATIO = 0.999

#: Smallest ratio of a point support's positive weight (or friction weight, with ``mu(x, y)``)
#: to the largest. Below it the point next to the heavy one is a torsion the inverse map cannot
#: resolve in double precision: on points at the corners of a right triangle with weights
#: ``(1, r, r)`` and on two points with ``(1, r)`` (1,000 random loads each),
#: ``safety_factor(load(motion(L)))`` is within 2e-15 of 1 down to ``r = 1e-10``, 6e-13 at
#: 1e-11, 8e-11 at 1e-12, and from 1e-14 the inverse map fails (3 to 400 loads in 1,000).
MIN_WEIGHT_RATIO = 1e-10

#: Smallest distance between two point supports, as a fraction of the points' span: three
#: points at a span's corners and a fourth this close to one, 3,000 random loads each (spans
#: 0.01 and 1 m): no failure of the inverse map down to 1e-8, 2 at 1e-9, 3-6 at 1e-10
#: (repeated points are one support, :func:`~fixplan.surface.pressure.points`).
MIN_POINT_GAP_RATIO = 1e-7

#: Largest weight of the twists against the loads in a fit of measured pairs: on 200 noisy
#: pairs of an ellipsoid both fits solved up to 1e6 and failed at 1e8 (an indefinite ellipsoid,
#: an inaccurate quartic); the twist term dominates long before (keep it near 1).
MAX_FIT_WEIGHT = 1e4

#: Largest speed of a pusher [m/s].
MAX_SPEED = 1e3

#: Longest simulated time [s] (about eleven days).
MAX_DURATION = 1e6

#: Most integration steps of one simulation (each is a few quasi-static steps: about a minute
#: with the exact limit surface).
MAX_STEPS = 100_000
