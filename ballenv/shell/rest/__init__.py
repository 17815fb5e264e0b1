"""The shell at rest: its static equilibrium under its gas and point loads (Newton's method on the
total potential) and its linear vibration modes about that equilibrium."""
