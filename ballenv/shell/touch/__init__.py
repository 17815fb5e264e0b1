"""What the shell touches: the grounds' barriers and lagged Coulomb friction, the point-triangle and
edge-edge distances, the barrier between shells and within one with its collision detection and its
positive semi-definite projection, and the broad phase that lists the candidate pairs."""
