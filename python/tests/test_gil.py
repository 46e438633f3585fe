"""Long calls release the GIL: another Python thread finishes its work while they run."""

from __future__ import annotations

import threading

import spectral_skin as ss


def test_monte_carlo_lets_other_python_threads_run():
    started = threading.Event()
    done = threading.Event()
    result = {}

    def work():
        started.set()
        result["mc"] = ss.monte_carlo(550.0, photons=100_000, threads=1)
        done.set()

    t = threading.Thread(target=work)
    t.start()
    started.wait()
    # Pure-Python work of a few switch intervals (5 ms each): with the GIL held by the call it
    # could only finish after the call (a few hundred ms of photons); released, it finishes first.
    total = 0
    for i in range(300_000):
        total += i
    finished_first = not done.is_set()
    t.join()
    assert finished_first
    assert total == 300_000 * 299_999 // 2
    assert 0 < result["mc"].diffuse_reflectance < 1
