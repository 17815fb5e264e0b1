import threading

import numpy as np
import pytest
from numba import njit

from ballenv.envs.tickets import draw_ticket


@njit(nogil=True)
def _draw_many(counter, out):
    for k in range(out.shape[0]):
        out[k] = draw_ticket(counter)


def test_a_draw_returns_the_counter_and_adds_one():
    counter = np.array([7], dtype=np.int64)
    out = np.zeros(3, dtype=np.int64)
    _draw_many(counter, out)
    assert out.tolist() == [7, 8, 9]
    assert counter[0] == 10


def test_threads_drawing_at_once_get_every_number_exactly_once():
    # two threads in compiled code without the GIL, started together, a million draws each: a plain
    # read-add-write of the counter hands numbers out twice (it did in 7 of 10 trial runs on a
    # loaded 2-core machine)
    counter = np.zeros(1, dtype=np.int64)
    draws = [np.zeros(1_000_000, dtype=np.int64) for _ in range(2)]
    _draw_many(counter, np.zeros(1, dtype=np.int64))  # compile before the threads start
    counter[0] = 0
    start = threading.Barrier(len(draws))

    def draw(out):
        start.wait()
        _draw_many(counter, out)

    threads = [threading.Thread(target=draw, args=(out,)) for out in draws]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    every = np.sort(np.concatenate(draws))
    assert np.array_equal(every, np.arange(every.size))
    assert counter[0] == every.size
    assert all(np.all(np.diff(out) > 0) for out in draws)  # each thread's draws keep rising


def test_only_an_int64_array_is_a_counter():
    @njit
    def draw_from(counter):
        return draw_ticket(counter)

    with pytest.raises(Exception, match="draw_ticket"):
        draw_from(np.zeros(1, dtype=np.float64))
