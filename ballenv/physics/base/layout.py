"""Integer layouts of the stepper's arrays, each declared once by name.

A :class:`Layout` is an ordered table of named fields, each one or more consecutive slots; its
indices are plain ints that numba compiles as constants. The module constants below
(``COUNT_STEPS``, ``CLOCK_T``, ...) are read off these tables, so a new name shifts every later
index and grows the size with it; ``tests/physics/base/test_layout.py`` checks that every constant is in
range and that users (``SimulationStats``, the env's counters) cover the table.
"""

from collections import OrderedDict


class Layout:
    """Named fields of an integer-indexed array: ``index(name)``, ``slice(name)``, ``size``."""

    def __init__(self, *fields):
        self._fields = OrderedDict()
        start = 0
        for field in fields:
            name, width = (field, 1) if isinstance(field, str) else field
            if name in self._fields:
                raise ValueError(f"layout field {name!r} declared twice")
            self._fields[name] = (start, width)
            start += width
        self.size = start

    @property
    def names(self):
        return tuple(self._fields)

    def index(self, name):
        """First slot of field ``name``."""
        return self._fields[name][0]

    def slice(self, name):
        start, width = self._fields[name]
        return slice(start, start + width)


# why a trial step was rejected; the stepper returns minus the code (1, 2, ...)
REJECTIONS = OrderedDict(
    newton="Newton's iteration did not converge",
    energy="the step gained energy (more than the energy budget can take back)",
    intrusion="a node of one ring ended inside another ring",
    self_intersection="a ring's wall crossed itself",
)
REJECT_NEWTON, REJECT_ENERGY, REJECT_INTRUSION, REJECT_SELF_INTERSECTION = (
    1 + list(REJECTIONS).index(name) for name in ("newton", "energy", "intrusion", "self_intersection")
)
REJECTION_REASONS = {1 + k: text for k, text in enumerate(REJECTIONS.values())}

# what advance() returns
STATUS = Layout("done", "buffer_full", "step_too_small", "impulse_at_dt_min")
STATUS_DONE = STATUS.index("done")
STATUS_BUFFER_FULL = STATUS.index("buffer_full")
STATUS_STEP_TOO_SMALL = STATUS.index("step_too_small")
STATUS_IMPULSE_AT_DT_MIN = STATUS.index("impulse_at_dt_min")

# int64 counters of a run
COUNTERS = Layout(
    "steps",  # accepted steps
    "rejected",  # rejected steps, all reasons
    "newton",  # Newton corrections (linear solves) of accepted steps
    "grid",  # fixed steps: index of the last grid point reached
    "records",  # records written
    "events",  # event rows written
    "rejection",  # why the last step was rejected: a REJECT_ code
    ("by_reason", len(REJECTIONS)),  # rejected steps by REJECT_ code (slot code - 1)
    "impulse_rejected",  # adaptive steps rejected for a contact impulse above its bound
    "error_rejected",  # error-controlled steps rejected for a local error above tolerance
    "energy_projected",  # accepted (step, ring) pairs whose energy gain was removed
)
COUNT_STEPS = COUNTERS.index("steps")
COUNT_REJECTED = COUNTERS.index("rejected")
COUNT_NEWTON = COUNTERS.index("newton")
COUNT_GRID = COUNTERS.index("grid")
COUNT_RECORDS = COUNTERS.index("records")
COUNT_EVENTS = COUNTERS.index("events")
COUNT_REJECTION = COUNTERS.index("rejection")
COUNT_BY_REASON = COUNTERS.index("by_reason")
COUNT_IMPULSE_REJECTED = COUNTERS.index("impulse_rejected")
COUNT_ERROR_REJECTED = COUNTERS.index("error_rejected")
COUNT_ENERGY_PROJECTED = COUNTERS.index("energy_projected")
N_COUNTERS = COUNTERS.size

# float64 clock of a run
CLOCK = Layout(
    "t",  # time (s)
    "h",  # current step size (s)
    "energy_removed",  # energy removed by the energy budget so far (J)
    "collision_gain",  # energy collision impulses created so far (J)
    "boundary_work",  # work moving grounds did on the rings so far (J)
)
CLOCK_T = CLOCK.index("t")
CLOCK_H = CLOCK.index("h")
CLOCK_ENERGY_REMOVED = CLOCK.index("energy_removed")
CLOCK_COLLISION_GAIN = CLOCK.index("collision_gain")
CLOCK_BOUNDARY_WORK = CLOCK.index("boundary_work")
N_CLOCK = CLOCK.size

# columns of State.energy (J): a ring's energy, its free part (kinetic plus elastic and gas energy
# above the inflated circle at rest, gravity left out), its energy budget (the energy at the
# start plus what actuation, collision impulses and moving grounds gave it since) and its kinetic
# energy
ENERGY = Layout("total", "free", "budget", "kinetic")
ENERGY_TOTAL = ENERGY.index("total")
ENERGY_FREE = ENERGY.index("free")
ENERGY_BUDGET = ENERGY.index("budget")
ENERGY_MOTION = ENERGY.index("kinetic")

# Workspace.energy_tally of a trial step: rings whose energy the budget lowered, the energy it
# removed (J), the net energy the step's collision impulses created (J; 0 if they removed energy),
# the work moving grounds did on the rings (J)
TALLY = Layout("projected", "removed", "collision_gain", "boundary_work")
TALLY_PROJECTED = TALLY.index("projected")
TALLY_REMOVED = TALLY.index("removed")
TALLY_COLLISION_GAIN = TALLY.index("collision_gain")
TALLY_BOUNDARY_WORK = TALLY.index("boundary_work")

# columns of Model.grounds, a ground as described: unit normal n, offset d0 (m) at t = 0,
# friction coefficient, its kind (GROUND_PLANE, or a drum: GROUND_DRUM_INSIDE / GROUND_DRUM_OUTSIDE,
# the sign s of its distance s (|x - c| - R)), a drum's centre c (m) and radius R (m), a plane's
# constant velocity u (m/s), amplitude A (m) and angular frequency omega = 2 pi f (rad/s) of its
# oscillation along n, a drum's angular velocity Omega (rad/s) and spin-up time (s) (ground_motion.py)
GROUND = Layout(
    ("normal", 2), "offset", "friction", "kind", ("centre", 2), "radius",
    ("velocity", 2), "amplitude", "angular_frequency", "spin", "spin_up",
)  # fmt: skip
GROUND_NORMAL = GROUND.index("normal")
GROUND_OFFSET = GROUND.index("offset")
GROUND_FRICTION = GROUND.index("friction")
GROUND_KIND = GROUND.index("kind")
GROUND_CENTRE = GROUND.index("centre")
GROUND_RADIUS = GROUND.index("radius")
GROUND_VELOCITY = GROUND.index("velocity")
GROUND_AMPLITUDE = GROUND.index("amplitude")
GROUND_ANGULAR_FREQUENCY = GROUND.index("angular_frequency")
GROUND_SPIN = GROUND.index("spin")
GROUND_SPIN_UP = GROUND.index("spin_up")
# values of the kind column: a half-plane; a drum with the rings inside it (s = -1) or outside it (s = +1)
GROUND_PLANE = 0.0
GROUND_DRUM_INSIDE = -1.0
GROUND_DRUM_OUTSIDE = 1.0

# columns of Workspace.surface, a ground at one time t: unit normal n, offset d(t) (m), friction
# coefficient, kind, drum centre and radius (the first eight as in GROUND, so the contact code reads
# either), a plane's surface velocity w(t) (m/s) and acceleration along n (m/s^2), a drum's angular
# velocity Omega(t) (rad/s) and the angle (rad) it has turned since t = 0
SURFACE = Layout(
    ("normal", 2), "offset", "friction", "kind", ("centre", 2), "radius",
    ("velocity", 2), "normal_acceleration", "spin", "turn",
)  # fmt: skip
SURFACE_NORMAL = SURFACE.index("normal")
SURFACE_OFFSET = SURFACE.index("offset")
SURFACE_FRICTION = SURFACE.index("friction")
SURFACE_KIND = SURFACE.index("kind")
SURFACE_CENTRE = SURFACE.index("centre")
SURFACE_RADIUS = SURFACE.index("radius")
SURFACE_VELOCITY = SURFACE.index("velocity")
SURFACE_NORMAL_ACCELERATION = SURFACE.index("normal_acceleration")
SURFACE_SPIN = SURFACE.index("spin")
SURFACE_TURN = SURFACE.index("turn")
# the contact code reads a ground's shape and friction from either table: the shared columns agree
SHARED_GROUND_COLUMNS = ("normal", "offset", "friction", "kind", "centre", "radius")
for _name in SHARED_GROUND_COLUMNS:
    if GROUND.slice(_name) != SURFACE.slice(_name):
        raise AssertionError(f"layout: GROUND and SURFACE disagree on column {_name!r}")

# rows of the event buffer: t (s), ring, kind (EVENT_KINDS), centre-of-mass height (m)
EVENT = Layout("t", "ring", "kind", "height")
EVENT_T = EVENT.index("t")
EVENT_RING = EVENT.index("ring")
EVENT_KIND = EVENT.index("kind")
EVENT_HEIGHT = EVENT.index("height")
EVENT_KINDS = ("touchdown", "liftoff", "apex")
EVENT_TOUCHDOWN, EVENT_LIFTOFF, EVENT_APEX = range(len(EVENT_KINDS))

# columns of Drive.ramp, a ring's gas ramp (drive.py): the gas amount (Pa m^(2k)) moves linearly in
# time from amount_start at t_start to amount_end at t_end (s); rest_ (J) and slope_ (J per
# Pa m^(2k)) are the rest energy (Model.rest_energy) at those amounts and its derivative in the
# amount, which interpolate it in between. Off (no ramp, the ring holds amount_end): t_end = -inf.
RAMP = Layout(
    "t_start", "t_end", "amount_start", "amount_end", "rest_start", "rest_end", "slope_start", "slope_end"
)
RAMP_T_START = RAMP.index("t_start")
RAMP_T_END = RAMP.index("t_end")
RAMP_AMOUNT_START = RAMP.index("amount_start")
RAMP_AMOUNT_END = RAMP.index("amount_end")
RAMP_REST_START = RAMP.index("rest_start")
RAMP_REST_END = RAMP.index("rest_end")
RAMP_SLOPE_START = RAMP.index("slope_start")
RAMP_SLOPE_END = RAMP.index("slope_end")

# columns of Drive.push, a ring's spread impulse (drive.py): momentum (x, y) (N s) delivered at a
# constant rate over [t_start, t_end] (s), of which the fraction `delivered` so far. Off: t_end = -inf.
PUSH = Layout("t_start", "t_end", "x", "y", "delivered")
PUSH_T_START = PUSH.index("t_start")
PUSH_T_END = PUSH.index("t_end")
PUSH_X = PUSH.index("x")
PUSH_Y = PUSH.index("y")
PUSH_DELIVERED = PUSH.index("delivered")
