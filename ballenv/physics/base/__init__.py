"""What every part of the simulator stands on: the compiled-kernel decorator and numba's compile
lock and notice, the packed arrays' layouts (declared once, by name), the banded linear algebra of
the Newton systems, polygon geometry and a ring's geometry and material (SI units)."""
