"""The shell's linear algebra: the block-sparse assembly of its element matrices, block-Jacobi-
preconditioned CG (for one shell and for a joint step), the envelope Cholesky with the gas's rank-one
term, and the linear solve of an implicit step's Newton system."""
