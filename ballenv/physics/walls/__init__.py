"""What keeps walls apart: the self-contact barrier of a ring's far wall parts, the wall limits of
a fold, the barrier between rings (solved jointly), the explicit impulses between rings and within
a ring, and their broad phases."""
