"""Cyclic neighbour indices of a ring's nodes (branches instead of integer modulo in hot loops)."""

from .jit import kernel


@kernel
def prev_node(i, n):
    """Index of the node before ``i`` on a ring of ``n`` nodes."""
    return i - 1 if i > 0 else n - 1


@kernel
def next_node(i, n):
    """Index of the node after ``i`` on a ring of ``n`` nodes."""
    return i + 1 if i < n - 1 else 0
