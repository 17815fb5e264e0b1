"""Broad phases: which pairs of rings, or of a ring's nodes and edges, may touch.

Both sort and sweep along x: the items are kept ordered by the left edge of their boxes
(:func:`sort_by`: insertion sort of an order kept from the previous call, nearly sorted between
steps, so O(n)); each item is compared with the following ones only until their left edge passes
its right edge. :func:`overlapping_pairs` finds the pairs of rings whose grown boxes overlap (the
explicit impulses and the barrier between rings), ``self_barrier.find_pairs`` the (node, edge)
pairs of one ring (the self-contact barrier).
"""

import math

from ..base.jit import kernel


@kernel(inline="always")
def sort_by(order, key):
    """Reorder the indices ``order`` in place so that ``key[order[k]]`` ascends (insertion sort:
    O(n) on an order that was sorted for keys that moved a little)."""
    for k in range(1, order.shape[0]):
        item = order[k]
        value = key[item]
        j = k - 1
        while j >= 0 and key[order[j]] > value:
            order[j + 1] = order[j]
            j -= 1
        order[j + 1] = item


@kernel
def ring_boxes(x, box):
    """``box[r] = (xmin, ymin, xmax, ymax)`` (m) of ring ``r``'s nodes."""
    for r in range(x.shape[0]):
        x_lo = y_lo = math.inf
        x_hi = y_hi = -math.inf
        for i in range(x.shape[1]):
            x_lo = min(x_lo, x[r, i, 0])
            x_hi = max(x_hi, x[r, i, 0])
            y_lo = min(y_lo, x[r, i, 1])
            y_hi = max(y_hi, x[r, i, 1])
        box[r, 0] = x_lo
        box[r, 1] = y_lo
        box[r, 2] = x_hi
        box[r, 3] = y_hi


@kernel
def overlapping_pairs(box, margin, order, left, pairs):
    """Ring pairs (a, b), a < b, whose boxes grown by ``margin[a]`` and ``margin[b]`` (m) overlap,
    into ``pairs``; returns their number. Rings in ``order`` sorted by their grown boxes' left edge
    (``left``, m: scratch of one entry per ring), then swept."""
    n = box.shape[0]
    for r in range(n):
        left[r] = box[r, 0] - margin[r]
    sort_by(order, left)
    count = 0
    for k in range(n):
        a = order[k]
        right = box[a, 2] + margin[a]
        for q in range(k + 1, n):
            b = order[q]
            if left[b] > right:
                break
            if (
                box[b, 1] - margin[b] <= box[a, 3] + margin[a]
                and box[a, 1] - margin[a] <= box[b, 3] + margin[b]
            ):
                pairs[count, 0] = min(a, b)
                pairs[count, 1] = max(a, b)
                count += 1
    return count
