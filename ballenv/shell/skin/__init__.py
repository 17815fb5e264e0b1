"""The shell's skin: its icosphere mesh; the energies of the skin and the gas (membrane stretching,
hinge bending, the enclosed gas, their total potential) with their exact derivatives; the damping of
its deformation; and the compiled model records built from a ``Shell``."""
