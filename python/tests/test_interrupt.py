"""Ctrl-C during a render, the GIL while rendering, progress."""

from __future__ import annotations

import faulthandler
import os
import signal
import sys
import threading
import time
import types

import numpy as np
import pytest

import foton
from conftest import SCENES, TINY

BOX = SCENES / "cornell-box.toml"


def long_render_scene():
    # 64x48 at up to a million spp: minutes, unless stopped.
    return foton.load(BOX, **{"film.width": 64, "film.height": 48})


@pytest.fixture(autouse=True)
def no_hang():
    """A render that a lost signal leaves running ends the test process with every thread's
    traceback after a minute, instead of hanging CI."""
    faulthandler.dump_traceback_later(60, exit=True)
    yield
    faulthandler.cancel_dump_traceback_later()


def sigint_after(seconds: float) -> threading.Timer:
    """SIGINT to this process from another thread, as a terminal's Ctrl-C would send it.

    Python's own SIGINT handler is installed first: a process started in the background by a
    shell without job control (`cmd &` in a script, nohup) inherits SIGINT ignored, Python then
    keeps it ignored, and the signal would never reach the render (the test hung that way)."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(seconds, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    return timer


def test_ctrl_c_stops_the_render_and_attaches_the_partial_image():
    scene = long_render_scene()
    sent = time.perf_counter() + 0.5
    timer = sigint_after(0.5)
    with pytest.raises(KeyboardInterrupt) as e:
        scene.render(spp=1_000_000, progress=False)
    stopped = time.perf_counter()
    timer.join()
    assert stopped - sent < 2.0, f"the render went on for {stopped - sent:.2f} s after Ctrl-C"
    image, info = e.value.image, e.value.render_info
    assert image.shape == (48, 64, 3) and image.dtype == np.float32
    assert info["interrupted"] is True
    assert 0 < info["samples"] < 64 * 48 * 1_000_000
    # The partial image is an estimate of the same picture: close to a finished render's mean.
    assert np.isfinite(image).all()
    full = scene.render(spp=8, progress=False)
    assert abs(image.mean() - full.mean()) < 0.1 * full.mean()
    assert scene.last_render["interrupted"] is False


def test_ctrl_c_stops_a_progressive_render():
    scene = foton.load(SCENES / "caustics-area.toml", **{"film.width": 32, "film.height": 24,
                                                          "integrators.sppm.iterations": 100000,
                                                          "integrators.sppm.photons_per_iteration": 2000})
    timer = sigint_after(0.5)
    with pytest.raises(KeyboardInterrupt) as e:
        scene.render(progress=False)
    timer.join()
    info = e.value.render_info
    assert info["interrupted"] and 0 < info["iterations"] < 100000
    assert info["iterations_planned"] == 100000
    assert e.value.image.any()


def test_the_gil_is_free_while_rendering():
    scene = long_render_scene()
    ticks: list[float] = []
    stop = threading.Event()

    def python_work():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            sum(range(200))  # pure Python: needs the GIL

    worker = threading.Thread(target=python_work)
    worker.start()
    try:
        start = time.perf_counter()
        # One render thread, so that the Python thread has a core of its own.
        # About 1.5 s on a quiet 2-core machine: five times what the check below needs.
        scene.render(spp=512, threads=1, progress=False)
        end = time.perf_counter()
    finally:
        stop.set()
        worker.join()
    took = end - start
    during = [t for t in ticks if start <= t <= end]
    assert took > 0.3, f"the render must take long enough to tell ({took:.2f} s)"
    # Held, the GIL would stop the Python thread for the whole render.
    assert len(during) > 100, f"the Python thread ran {len(during)} times in {took:.2f} s"
    gaps = np.diff([start, *during, end])
    assert gaps.max() < took / 3, f"the Python thread was held up for {gaps.max():.3f} of {took:.2f} s"


def test_renders_in_two_threads_at_once():
    scene = foton.load(BOX, **TINY)
    results = {}

    def render(seed):
        results[seed] = scene.render(spp=4, seed=seed, threads=1, progress=False)

    threads = [threading.Thread(target=render, args=(s,)) for s in (1, 2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert np.array_equal(results[1], scene.render(spp=4, seed=1, progress=False))
    assert np.array_equal(results[2], scene.render(spp=4, seed=2, progress=False))


def test_progress_callback():
    calls = []
    scene = foton.load(SCENES / "caustics-area.toml", **TINY)
    scene.render(integrator="photon", spp=2, progress=lambda *a: calls.append(a))
    assert calls, "the callback was called"
    for phase, done, total in calls:
        assert isinstance(phase, str) and phase
        assert 0 <= done <= total
    # Each phase begins with done = 0 and ends complete: split the calls at each 0.
    phases = []
    for phase, done, total in calls:
        if done == 0:
            phases.append([])
        assert phases, "the first report begins a phase"
        phases[-1].append((phase, done, total))
    names = [p[0][0] for p in phases]
    # Two photon passes (global and caustic maps), then the pixels.
    assert names == ["photons", "photons", "pixels"], names
    for p in phases:
        assert p[-1][1] == p[-1][2], p[-1]


def test_an_exception_in_the_callback_stops_the_render():
    scene = long_render_scene()

    def stop_soon(phase, done, total):
        if done > 0:
            raise ValueError("enough")

    with pytest.raises(ValueError, match="enough") as e:
        scene.render(spp=1_000_000, progress=stop_soon)
    assert e.value.render_info["interrupted"]
    assert e.value.image.shape == (48, 64, 3)


def fake_tqdm(monkeypatch):
    bars = []

    class Bar:
        def __init__(self, total, desc, leave):
            self.total, self.desc, self.n, self.closed = total, desc, 0, False
            bars.append(self)

        def update(self, n):
            self.n += n

        def close(self):
            self.closed = True

    module = types.ModuleType("tqdm.auto")
    module.tqdm = Bar
    monkeypatch.setitem(sys.modules, "tqdm", types.ModuleType("tqdm"))
    monkeypatch.setitem(sys.modules, "tqdm.auto", module)
    return bars


def test_a_tqdm_bar_per_phase(monkeypatch):
    bars = fake_tqdm(monkeypatch)
    sets = dict(TINY, **{"integrators.photon.caustic_photons": 5000})
    foton.load(SCENES / "caustics-area.toml", **sets).render(integrator="photon", spp=2)
    assert [(b.desc, b.total) for b in bars] == [("photons", 3000), ("photons", 5000), ("pixels", 40 * 30 * 2)]
    assert all(b.closed and b.n == b.total for b in bars)
    bars.clear()
    foton.load(BOX, **TINY).render(spp=1, progress=False)
    assert not bars


def test_without_tqdm_there_is_no_bar(monkeypatch):
    monkeypatch.setitem(sys.modules, "tqdm", None)
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)
    assert foton.load(BOX, **TINY).render(spp=1).any()
