"""One time step of the shells: the implicit step of one shell (backward Euler or generalized-alpha),
its incremental potential and preallocated records; the joint step of shells that may touch, its
records and the grouping; the energy budget; and the events located inside a step."""
