"""One time step of the rings and its control: the integrators, Newton's iteration for one ring and
for rings in contact, the local and contact error estimates, the energy budget, the events located
inside a step, actuation between and during steps, and the stepper that runs the phases."""
