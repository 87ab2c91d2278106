"""The native update's kept worker threads (csrc/include/bearing_core/core/worker_pool.hpp):
the same maps whatever runs them, from a forked child and from two Python threads at once."""

from __future__ import annotations

import multiprocessing
import threading

import numpy as np
import pytest
from numpy.typing import NDArray

from bearing_env.slam import BatchedPolygonSLAM, kernels
from bearing_env.slam.batch import STATE_ARRAYS

EPS = np.deg2rad(2.0)
MAPS, LANDMARKS, MOVES = 24, 5, 6


def readings(seed: int) -> list[tuple[NDArray[np.float64], NDArray[np.float64]]]:
    """Noise-free bearings (MAPS, LANDMARKS) at both ends of MOVES random moves, one
    random world per map."""
    rng = np.random.default_rng(seed)
    landmarks = rng.uniform(-1, 1, (MAPS, LANDMARKS)) + 1j * rng.uniform(-1, 1, (MAPS, LANDMARKS))
    position = np.zeros(MAPS, dtype=np.complex128)
    moves = []
    for _ in range(MOVES):
        turn = np.exp(-1j * rng.uniform(-np.pi, np.pi, MAPS))[:, None]  # world to robot
        end = position + 0.4 / turn[:, 0]
        start_bearings = np.angle((landmarks - position[:, None]) * turn)
        end_bearings = np.angle((landmarks - end[:, None]) * turn)
        moves.append((np.ascontiguousarray(start_bearings), np.ascontiguousarray(end_bearings)))
        position = end
    return moves


def run(seed: int, threads: int) -> dict[str, NDArray[np.generic]]:
    """Every state array after MOVES updates of MAPS maps on ``threads`` threads."""
    batch = BatchedPolygonSLAM(MAPS, LANDMARKS, EPS)
    rows = np.arange(MAPS)
    for b1, b2 in readings(seed):
        out = kernels.Outputs(
            np.empty(MAPS, dtype=np.int8),
            np.empty((MAPS, LANDMARKS - 2), dtype=np.int8),
            np.empty(MAPS, dtype=np.int64),
        )
        kernels.update_maps(
            b1, b2, rows, batch._kernel_params(True), batch._kernel_state(), out, threads
        )
    return {name: getattr(batch, name).copy() for name in STATE_ARRAYS}


def assert_same_maps(
    mine: dict[str, NDArray[np.generic]], theirs: dict[str, NDArray[np.generic]]
) -> None:
    for name in STATE_ARRAYS:
        np.testing.assert_array_equal(mine[name], theirs[name], err_msg=name)
    assert int(mine["n_frame_changes"].sum()) > MAPS  # real movements were fused


def child_run(seed: int, queue: multiprocessing.Queue[dict[str, NDArray[np.generic]]]) -> None:
    queue.put(run(seed, threads=2))


def test_a_forked_child_updates_on_threads_of_its_own() -> None:
    parent = run(1, threads=2)  # the parent's workers exist before the fork
    context = multiprocessing.get_context("fork")
    queue: multiprocessing.Queue[dict[str, NDArray[np.generic]]] = context.Queue()
    child = context.Process(target=child_run, args=(1, queue))
    child.start()
    result = queue.get(timeout=120)  # a child waiting on the parent's threads never answers
    child.join(timeout=60)
    assert child.exitcode == 0
    assert_same_maps(result, parent)
    assert_same_maps(run(1, threads=2), parent)  # and the parent's workers still run


def test_two_python_threads_updating_at_once_get_the_serial_maps() -> None:
    serial = {seed: run(seed, threads=1) for seed in (2, 3)}
    results: dict[int, dict[str, NDArray[np.generic]]] = {}
    errors: list[BaseException] = []

    def worker(seed: int) -> None:
        try:
            for _ in range(5):  # repeated, so that the two calls overlap
                results[seed] = run(seed, threads=3)
        except BaseException as error:  # reported by the main thread
            errors.append(error)

    threads = [threading.Thread(target=worker, args=(seed,)) for seed in (2, 3)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join(timeout=300)
    assert not errors and all(not thread.is_alive() for thread in threads)
    for seed in (2, 3):
        assert_same_maps(results[seed], serial[seed])


def test_the_thread_count_comes_from_the_variable_or_the_cpus(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.delenv(kernels.THREADS_VARIABLE, raising=False)
    assert kernels.threads() >= 1
    monkeypatch.setenv(kernels.THREADS_VARIABLE, "3")
    assert kernels.threads() == 3
    for bad in ("0", "two", "-1"):
        monkeypatch.setenv(kernels.THREADS_VARIABLE, bad)
        with pytest.raises(ValueError, match=f"{kernels.THREADS_VARIABLE}.*{bad!r}"):
            kernels.threads()


def test_an_error_in_a_workers_block_reaches_the_caller_and_the_workers_go_on() -> None:
    batch = BatchedPolygonSLAM(MAPS, LANDMARKS, EPS)
    batch.counts[MAPS - 1, 0] = 10**6  # a corrupt map in the last block, a worker's
    b1, b2 = readings(4)[0]
    out = kernels.Outputs(
        np.empty(MAPS, dtype=np.int8),
        np.empty((MAPS, LANDMARKS - 2), dtype=np.int8),
        np.empty(MAPS, dtype=np.int64),
    )
    arguments = (b1, b2, np.arange(MAPS), batch._kernel_params(True), batch._kernel_state(), out)
    with pytest.raises(ValueError, match=f"map {MAPS - 1} has a corrupt state"):
        kernels.update_maps(*arguments, 2)
    assert_same_maps(run(5, threads=2), run(5, threads=1))  # the workers still answer
